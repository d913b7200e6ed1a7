"""What a narration is asked for, in one object: :func:`xairl.narrate` and :meth:`xairl.plugin.Narrator.narrate` take
it (or its fields as keyword arguments) and hand it on whole, and the confidence reads its policy, background and
robustness from it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import ConfigDict, Field

from xairl.options import Options, parse_options
from xairl.policies.policy import Policy


class NarrationOptions(Options):
    """How to narrate a decision (or the global view); unknown names are an error."""

    model_config = ConfigDict(extra="forbid", frozen=True, arbitrary_types_allowed=True)

    template: str | Path | None = None
    """Template name or .yaml path; default 'explain_action' (or 'global_summary', or 'explain_output' for a policy
    that chooses no action)."""
    policy: Policy | None = None
    """Gives feature descriptions, domain facts, and (with ``background``) the robustness parts of the confidence."""
    background: Any = None
    """The background states: the robustness parts of the confidence explain the state again with them, and a
    counterfactual search is bounded by them."""
    prompt_dirs: tuple[str | Path, ...] = ()
    """Extra template folders, searched first."""
    k: int = Field(3, ge=1)
    """How many features the facts list."""
    robustness: bool = True
    """Measure agreement and stability (three extra explanations of the state)."""
    history: Any = None
    """The states before the narrated one in the same episode (oldest first), for a policy whose ``facts_hook`` states
    facts over time ("the neighbour has been stronger for 3 decisions")."""
    counterfactual: Any = False
    """True: search what would have changed the decision (it needs ``policy``; the search is guided by the explanation
    and bounded by ``background``) and give the template its fact, or the search's answer for this state
    (:class:`xairl.Counterfactuals`); its sentence is checked by running the policy on it. Discrete actions only, one
    decision (not ``index=None``); anything else is refused."""

    @classmethod
    def of(cls, narration: NarrationOptions | None = None, **given) -> NarrationOptions:
        """``narration`` (default: the defaults) with the fields given as keyword arguments replaced; a name that is
        no field, or a value of the wrong type, is one line (:class:`xairl.InputError`)."""
        base = narration if narration is not None else cls()
        if not isinstance(base, cls):
            base = parse_options(cls, base, "narration options")
        return parse_options(cls, {**dict(base), **given}, "narration options") if given else base
