"""Sample facts for trial renderings of a template (``xairl prompts check``, :func:`xairl.plugin.check_template`):
plausible values of every variable a decision or global template may use."""

from __future__ import annotations

from xairl.counterfactual_facts import ChangeFact, CounterfactualFact
from xairl.facts import Comparison, DecisionFacts, FeatureFact, GlobalFacts


class _SampleExtras(dict):
    """Plugin-defined extras are unknown to the core: any key reads as 1 in a trial rendering."""

    def __missing__(self, key):
        return 1


def sample_context(kind: str) -> dict:
    """Plausible facts of a template ``kind`` ('decision' or 'global'), for trial renderings
    (:func:`xairl.narrators.check_template`)."""
    if kind == "global":
        return GlobalFacts(
            10,
            "deep_shap",
            tuple(
                {
                    "name": f"f{i}",
                    "label": f"feature {i}",
                    "unit": "",
                    "rank": i,
                    "mean_abs": 1.0 / i,
                    "mean": 0.5 / i,
                    "direction": "toward",
                    "high_values": "toward",
                    "low_values": "against",
                }
                for i in range(1, 4)
            ),
        ).context()
    feats = tuple(
        FeatureFact(f"f{i}", f"feature {i}", 1.0, "m", 0.5 / i, 30.0, "toward", "high", "high", i, value_text="1.00 m")
        for i in range(1, 4)
    )
    against = FeatureFact("f4", "feature 4", 2.0, "m", -0.1, 10.0, "against", "low", "low", 4, value_text="2.00 m")
    ident = FeatureFact(
        "f5", "feature 5", 15.0, "", 0.0, 0.0, "toward", "unknown", "", 0, "identifier", value_text="15"
    )
    return DecisionFacts(
        0,
        "a",
        "b",
        1.0,
        0.5,
        0.5,
        0.2,
        "deep_shap",
        0.0,
        feats,
        feats,
        (Comparison("x is 1 dB above y", 1.0, "dB"),),
        {},
        reasons=feats,
        concession=against,
        base_margin=0.1,
        identifiers=(ident,),
        counterfactual=CounterfactualFact(
            True,
            (ChangeFact("f1", "feature 1", "m", 1.0, "1.00 m", 0.5, "0.50 m", "below"),),
            "b",
            "b",
            0.2,
            "a",
            "",
            2,
        ),
    ).context() | {"extras": _SampleExtras()}
