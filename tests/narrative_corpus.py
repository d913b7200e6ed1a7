"""The verifier's narrative corpora, loaded for the tests and for the benchmarks that measure the reader on them
(``benchmarks/bench_verifier.py``, ``benchmarks/bench_heldout.py``): the corpus in ``benchmarks/data/narratives``,
its later voices, the held-out and tuning voices, the outside SHAPstories cases, and one-output explanations built
from what a narrative says."""

from __future__ import annotations

import functools
import json
import pathlib
import re
import time
from dataclasses import replace

import numpy as np
import yaml

import xairl
from tests import narrative_domains as domains

DATA = pathlib.Path(__file__).resolve().parents[1] / "benchmarks" / "data" / "narratives"
HELDOUT = DATA / "heldout"


# the narratives written after the first corpus, one folder a set of voices under voices/, named by split and voice
VOICES = tuple(sorted(p.name for p in (DATA / "voices").iterdir() if p.is_dir()))


SPLITS = ("dev", *(v for v in VOICES if v.startswith("dev-")), "test", *(v for v in VOICES if v.startswith("test-")))


def load_corpus() -> list[dict]:
    """Every narrative with its case's Explanation, domain, split, label and error kind. Beside the first corpus, it holds the
    narratives written later in other voices (``voices/dev-*`` on the dev cases, tuning material like ``dev``;
    ``voices/test-*`` on the test cases, never tuned on)."""
    cases = {
        c["id"]: c
        for path in (DATA / "cases.json", DATA / "voices" / "dev-qa-shorthand-lists" / "cases.json")
        for c in json.loads(path.read_text())
    }
    out = []
    for domain in domains.DOMAINS:
        for later in (None, *(s for s in SPLITS if s not in ("dev", "test"))):
            path = (DATA / "voices" / later if later else DATA) / f"{domain}.yaml"
            for case_id, items in yaml.safe_load(path.read_text()).items():
                case = cases[case_id]
                split = later.split("-")[0] if later else None  # voices/dev-* on dev cases, voices/test-* on test
                assert not later or case["split"] == split, f"{path}: {case_id} is not a {split} case"
                exp = xairl.Explanation.from_json(json.dumps(case["explanation"]))
                for item in items:
                    ((label, text),) = item.items()
                    out.append(
                        {
                            "case": case_id,
                            "domain": domain,
                            "split": later or case["split"],
                            "error": label,
                            "accurate": label == "ok",
                            "text": text,
                            "explanation": exp,
                        }
                    )
    return out


def run(items: list[dict], policies: dict) -> list[dict]:
    """Verify every item with ``xairl.verify`` (outside prose: the rule-table reader)."""
    from xairl.verification import verify

    for it in items:
        t = time.perf_counter()
        res = verify(it["text"], it["explanation"], 0, it.get("policy") or policies.get(it["domain"]))
        it["seconds"] = time.perf_counter() - t
        it["sentences"] = max(1, len(re.findall(r"[.!?\n](\s|$)", it["text"].strip() + " ")))
        it["ok"] = res.ok
        it["result"] = res
    return items


def explanation_from_tuples(text: str, output: str = "prediction") -> xairl.Explanation:
    """A one-output Explanation from '(name, value, contribution), ...' tuples, as Explingo writes them (a value that
    is not a number is a category); no baseline is given, so it is 0."""
    tuples = re.findall(r"\(([^()]*?),\s*([^,()]+?),\s*(-?[\d.]+)\)", text)
    values = [float(v) if re.fullmatch(r"-?[\d.]+", v.strip()) else v.strip() for _, v, _ in tuples]
    return one_output([t[0].strip() for t in tuples], values, [float(t[2]) for t in tuples], output=output)


def one_output(
    names: list[str], values: list, contributions: list[float], base: float = 0.0, output: str = "prediction"
) -> xairl.Explanation:
    """A one-output Explanation of one state: each feature's value (a str is a category's label) and contribution;
    the prediction is the baseline plus their sum."""
    cats = {n: (v,) for n, v in zip(names, values) if isinstance(v, str)}
    states = np.array([[0.0 if isinstance(v, str) else float(v) for v in values]])
    contrib = np.array(contributions, dtype=float)
    return xairl.Explanation(
        values=contrib.reshape(1, -1, 1),
        base_values=np.array([[base]]),
        outputs=np.array([[base + contrib.sum()]]),
        states=states,
        feature_names=tuple(names),
        action_names=(output,),
        method="given",
        output="value",
        categories=cats or None,
    )


@functools.cache
def shapstories_cases() -> dict:
    """``data/narratives/outside/shapstories.yaml``, read once."""
    return yaml.safe_load((DATA / "outside" / "shapstories.yaml").read_text())


def shapstories_case(dataset: str, index: int) -> tuple[int, xairl.Explanation, xairl.Policy]:
    """(batch, Explanation, Policy) built for narrative ``index`` of ``dataset`` in
    ``data/narratives/outside/shapstories.yaml``: one output, the data dictionary's descriptions and categories."""
    import torch

    domain = shapstories_cases()[dataset]
    batch, prediction, given = domain["cases"][index]
    feats = domain["features"]
    names = tuple(feats)
    cats = {f: tuple(d[1]) for f, d in feats.items() if isinstance(d[1], list)}
    value = {f: (cats[f].index(v) if f in cats else v) for f, (v, _) in given.items()}
    states = np.array(
        [[value.get(f, min(2, len(cats[f]) - 1) if f in cats else feats[f][2]) for f in names]], float
    )  # else the median (a category: its third code)
    contrib = np.array([given[f][1] if f in given else 0.001 for f in names])
    quartiles = np.array([[np.nan if f in cats else feats[f][k] for f in names] for k in (1, 2, 3)], float)
    exp = xairl.Explanation(
        values=contrib.reshape(1, -1, 1),
        base_values=np.array([[prediction - contrib.sum()]]),
        outputs=np.array([[prediction]]),
        states=states,
        feature_names=names,
        action_names=(domain["output"],),
        method="given",
        output="value",
        background_quantiles=quartiles,
        categories=cats or None,
    )
    info = {
        f: xairl.FeatureInfo(d[4] if len(d) > 4 else "", d[0], categories=cats.get(f, ())) for f, d in feats.items()
    }
    policy = xairl.Policy(
        torch.nn.Linear(len(names), 1), list(names), [domain["output"]], features=info, output="value", name=dataset
    )
    return batch, exp, policy


def manipulated(exp: xairl.Explanation) -> list[tuple[str, xairl.Explanation]]:
    """The narrative's explanation changed the way SHAPnarrative-metrics manipulates SHAP tables, so that the same
    (accurate) text becomes wrong: every contribution's sign inverted (the prediction mirrored about the baseline),
    and the two largest contributions swapped."""
    values = exp.values.copy()
    order = np.argsort(-np.abs(values[0, :, 0]))
    swapped = values.copy()
    swapped[0, order[:2], 0] = values[0, order[1::-1], 0]
    base = exp.base_values
    return [
        ("inverted signs", replace(exp, values=-values, outputs=base - values.sum(axis=1))),
        ("top two swapped", replace(exp, values=swapped, outputs=base + swapped.sum(axis=1))),
    ]


def case_explanation(case: dict) -> xairl.Explanation:
    """A one-output Explanation from a case: [name, value, contribution] per feature (a string value is a category),
    the base value and the output's words."""
    names, values, contributions = zip(*[(str(f[0]), f[1], float(f[2])) for f in case["features"]])
    return one_output(
        list(names), list(values), list(contributions), float(case["base_value"]), case.get("output") or "prediction"
    )


def load(path: pathlib.Path) -> list[dict]:
    items = []
    for case in yaml.safe_load(path.read_text())["cases"]:
        exp = case_explanation(case)
        for entry in case["narratives"]:
            ((label, text),) = entry.items()
            items.append(
                {
                    "file": _name(path),
                    "case": case["id"],
                    "domain": case["domain"],
                    "error": label,
                    "accurate": label == "ok",
                    "text": text,
                    "explanation": exp,
                    "wrong_facts": False,
                }
            )
            if label == "ok":
                for kind, e in manipulated(exp):
                    items.append(
                        {
                            "file": _name(path),
                            "case": case["id"],
                            "domain": case["domain"],
                            "error": kind,
                            "accurate": False,
                            "text": text,
                            "explanation": e,
                            "wrong_facts": True,
                        }
                    )
    return items


def _name(path: pathlib.Path) -> str:
    return f"{'tuning' if path.parent.name == 'tuning' else 'held out'}: {path.stem}"


def share(items: list[dict], status: str) -> str:
    """How many of the verified ``items`` have ``status``, as 'n/N = x %' (the benchmarks' figures of issue 65)."""
    n = sum(it["result"].status == status for it in items)
    return f"{n}/{len(items)} = {100 * n / max(1, len(items)):.1f} %"
