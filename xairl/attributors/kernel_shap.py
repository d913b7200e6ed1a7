"""KernelSHAP through shap.KernelExplainer: model-agnostic, sampled coalitions, seeded."""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
import torch
from pydantic import Field

from xairl.attributors.base import Attributor, Options
from xairl.explanations.display import quiet_tqdm, show_progress


class KernelShapOptions(Options):
    nsamples: Annotated[int, Field(ge=1, le=10_000_000)] | Literal["auto"] = Field(
        "auto", description="coalitions evaluated per state; 'auto' = 2F + 2048"
    )
    l1_reg: bool | float | Literal["auto", "aic", "bic"] | Annotated[str, Field(pattern=r"^num_features\(\d+\)$")] = (
        Field(False, description="shap's feature selection; False keeps every feature")
    )
    seed: int = Field(0, ge=0, le=2**32 - 1, description="seed of the coalition sampler")
    progress: bool | None = Field(
        None,
        description="show shap's progress bar over the states: True, False, or None = only when stderr is a terminal",
    )


class KernelShap(Attributor):
    """KernelSHAP (Lundberg & Lee) via the shap package; all actions at once."""

    name = "kernel_shap"
    Options = KernelShapOptions

    def _attribute(self, policy, x, bg):
        quiet_tqdm()  # shap imports tqdm.auto, which warns 'IProgress not found' in a notebook without ipywidgets
        import shap

        dev = policy.device

        def f(rows: np.ndarray) -> np.ndarray:
            t = torch.as_tensor(np.asarray(rows, dtype=policy.dtype), device=dev)
            return self._forward(policy, t, 65_536).numpy()

        explainer = shap.KernelExplainer(f, bg)
        # shap samples coalitions from numpy's global generator: seed it here and put the caller's state back
        silent = not show_progress(self.options.progress)
        saved = np.random.get_state()
        np.random.seed(self.options.seed)
        try:
            sv = explainer.shap_values(x, nsamples=self.options.nsamples, l1_reg=self.options.l1_reg, silent=silent)
        finally:
            np.random.set_state(saved)
        values = np.stack(sv, axis=-1) if isinstance(sv, list) else np.asarray(sv)
        return values, np.asarray(explainer.expected_value, dtype=np.float64), {}
