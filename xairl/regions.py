"""An image explanation in regions: what narration, its verifier and the report's cards speak of instead of pixels.

An image of thousands of pixels is narrated patch by patch: each channel cut into square patches of about a tenth of
the image's side (:meth:`xairl.Observation.regions`), each patch one feature named in words ('the 8x8 patch at rows 24
to 31, columns 32 to 39 of channel 2'; rows, columns and channels count from 0, as in the pixels' names) whose
contribution is the sum of its pixels' and whose value is their mean. Narration and :func:`xairl.verify` both read an
image explanation through :func:`in_regions`, so a narrative's region names are the verifier's vocabulary.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .explanation import Explanation
from .observation import Observation


def in_regions(exp: Explanation) -> Explanation:
    """``exp`` with each image part's pixels grouped into named regions (other features as they are); ``exp`` itself
    when it has no image part with patches larger than a pixel (flat, small or already grouped explanations)."""
    if exp.observation is None:
        return exp
    groups = Observation.from_dict(exp.observation).regions()
    if not groups:
        return exp
    out = exp.grouped(groups)
    index = {f: j for j, f in enumerate(exp.feature_names)}
    members = [groups[f] if f in groups else np.array([index[f]]) for f in out.feature_names]
    states = None if exp.states is None else np.stack([exp.states[:, m].mean(axis=1) for m in members], axis=1)
    quartiles = None
    if exp.background_quantiles is not None:  # a region's quartiles are unknown (NaN: no level words)
        quartiles = np.stack([exp.background_quantiles[:, m[0]] if len(m) == 1 and out.feature_names[k] not in groups
                              else np.full(len(exp.background_quantiles), np.nan) for k, m in enumerate(members)],
                             axis=1)
    return replace(out, states=states, background_quantiles=quartiles)
