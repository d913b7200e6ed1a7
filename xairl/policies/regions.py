"""An image explanation in regions: what narration, its verifier and the report's cards speak of instead of pixels.

An image of thousands of pixels is narrated patch by patch: each channel cut into square patches of about a tenth of
the image's side (:meth:`xairl.Observation.regions`), each patch one feature named by its grid reference ('patch F6 of
channel 2', or 'of frame 2' in a frame stack, ``Observation.array(shape, channels="frames")``: column letters from the
left, row numbers from the top; channels and frames count from 0, as in the pixels' names) whose contribution is the
sum of its pixels' and whose value is their mean. The pixels each region covers ('the 8x8 patch at rows 40 to 47,
columns 40 to 47 of channel 2') are in the regioned explanation's ``extras["regions"]``, for tables and hover texts.
Narration and :func:`xairl.verify` both read an image explanation through :func:`in_regions`, so a narrative's region
names are the verifier's vocabulary (which also takes a region's extent as its name).

A frame stack's regions are a window over its frames (:class:`xairl.policies.windows.Window` with ``frames=True``): each
region a signal ('patch F6') whose slots are its patch in each frame ('patch F6 of frame 2'), so its narrative says
how a region changed over the stack ('the mean pixel value of patch F6 rose 40 over the last 4 frames') as any
window's trends are said.
"""

from __future__ import annotations

import weakref
from dataclasses import replace

import numpy as np

from xairl.explanations.explanation import Explanation
from xairl.policies.observation import Observation, Part
from xairl.policies.windows import Window

#: id of an explanation -> (a weak reference to it, its regioned copy): narrating, verifying and reporting a
#: decision each ask for the same regions (kept while the explanation lives)
_MEMO: dict[int, tuple[weakref.ref, Explanation]] = {}


def in_regions(exp: Explanation) -> Explanation:
    """``exp`` with each image part's pixels grouped into named regions (other features as they are), each region's
    extent in ``extras["regions"]`` (name -> 'the 8x8 patch at rows 40 to 47, columns 40 to 47 of channel 2'); ``exp``
    itself when it has no image part with patches larger than a pixel (flat, small or already grouped explanations)."""
    if exp.observation is None:
        return exp
    hit = _MEMO.get(id(exp))
    if hit is not None and hit[0]() is exp:
        return hit[1]
    out = _in_regions(exp)
    if out is not exp:
        key = id(exp)
        _MEMO[key] = (weakref.ref(exp, lambda _, key=key: _MEMO.pop(key, None)), out)
    return out


def _in_regions(exp: Explanation) -> Explanation:
    observation = Observation.from_dict(exp.observation)
    groups = observation.regions()
    if not groups:
        return exp
    out = exp.grouped(groups)
    index = {f: j for j, f in enumerate(exp.feature_names)}
    members = [groups[f] if f in groups else np.array([index[f]]) for f in out.feature_names]
    states = None if exp.states is None else np.stack([exp.states[:, m].mean(axis=1) for m in members], axis=1)
    quartiles = None
    if exp.background_quantiles is not None:  # a region's quartiles are unknown (NaN: no level words)
        quartiles = np.stack(
            [
                exp.background_quantiles[:, m[0]]
                if len(m) == 1 and out.feature_names[k] not in groups
                else np.full(len(exp.background_quantiles), np.nan)
                for k, m in enumerate(members)
            ],
            axis=1,
        )
    extents = observation.region_extents()
    extents = {f: extents[f] for f in out.feature_names if f in extents}
    window = _frame_window(observation, out.feature_names)
    if window is not None:  # a region over the frames: the pixels of its first frame's patch, in every frame
        first = window.names()[: len(window.signals)]
        extents |= {s: extents[f].replace(" of frame 0", " in every frame") for s, f in zip(window.signals, first)}
    return replace(
        out,
        states=states,
        background_quantiles=quartiles,
        observation=None
        if window is None
        else Observation("window", (Part("obs", window.shape, window=window),)).to_dict(),
        extras={**exp.extras, "regions": extents},
    )


def _frame_window(observation: Observation, names: tuple[str, ...]) -> Window | None:
    """A frame stack's regions over its frames, when ``names`` (the regioned features) are its slots."""
    groups = observation.time_groups()
    if groups is None or observation.kind != "array":
        return None
    regions, frames = groups
    window = Window(tuple(regions), len(frames), frames=True)
    return window if window.names() == list(names) else None
