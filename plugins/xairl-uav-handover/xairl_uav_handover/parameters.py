"""Every setting of the simulator and the baselines with its value and its source, as the table in
docs/uav-reference.md ("Every parameter and its source"). The sources live in the settings' own descriptions
(config.py), so the table cannot drift from the code: ``python -m xairl_uav_handover.parameters`` prints it, and a
test checks that the docs hold exactly this table.
"""

from __future__ import annotations

from pydantic import BaseModel

from .baselines import CHMConfig, SAMROConfig
from .config import SimConfig

#: where the docs table starts and ends
BEGIN, END = "<!-- parameters: begin -->", "<!-- parameters: end -->"


def rows(model: BaseModel, prefix: str = "") -> list[tuple[str, str, str]]:
    """(name, value, source) for every leaf setting of ``model``, nested sections as ``section.field``."""
    out = []
    for name, field in type(model).model_fields.items():
        value = getattr(model, name)
        if isinstance(value, BaseModel):
            out += rows(value, f"{prefix}{name}.")
        else:
            shown = ", ".join(f"{v:g}" for v in value) if isinstance(value, tuple) else f"{value}"
            out.append((f"{prefix}{name}", shown, " ".join((field.description or "").split())))
    return out


def table() -> str:
    """The markdown table of the simulator's, CHM's and SA-MRO's settings, with the value of the network calibrated
    to the real flights where it differs (network_check.CALIBRATED)."""
    from .network_check import calibrated

    tuned = {n: v for n, v, _ in rows(calibrated())}
    lines = [BEGIN, "| setting | value | calibrated network | source |", "|---|---|---|---|"]
    for model, prefix in ((SimConfig(), ""), (CHMConfig(), "chm."), (SAMROConfig(), "sa_mro.")):
        for n, v, s in rows(model, prefix):
            other = tuned.get(n, v) if not prefix else v
            lines.append(f"| `{n}` | {v} | {other if other != v else ''} | {s.replace('|', '/')} |")
    return "\n".join([*lines, END])


def undocumented() -> list[str]:
    """Settings whose description is empty: each needs its source or the measurement it was fitted to."""
    return [n for model in (SimConfig(), CHMConfig(), SAMROConfig()) for n, _, s in rows(model) if not s]


if __name__ == "__main__":
    print(table())
