"""The evidence beside a narrated decision, and its HTML card.

An operator checks a narrative against the state and the numbers: :func:`evidence` collects them (the decision,
every feature's value and contributions to the margin over the runner-up and to the chosen score, each sentence's
verification status, the verdict on the whole text with its claim coverage and its account of the margin, the
confidence components; a decision's counterfactuals where they were searched, under
``'counterfactual'``) as plain JSON-ready data; the feedback store keeps it with the narrative, and :func:`card_html`
draws the same card in the HTML report and on the review page.
"""

from __future__ import annotations

import html
import re
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np

from xairl.explanations.display import CF_STYLE, counterfactual_html
from xairl.explanations.explanation import Explanation

#: how many contributions the card's waterfall shows (the rest as one bar)
SHOWN = 8
STATUS_MARK = {"verified": "&#10003;", "contradicted": "&#10007;", "unchecked": "?", "none": ""}
#: the three verdicts on a text (:attr:`xairl.Verification.status`), worst last
VERDICTS = ("verified", "partly checked", "contradicted")


def verdict_text(status: str, coverage: float | None = None) -> str:
    """How every surface says a verdict: 'verified', 'contradicted' or 'partly checked (coverage 62 %)'."""
    if status == "partly checked" and coverage is not None:
        return f"partly checked (coverage {100 * coverage:.0f} %)"
    return status


def verdict_of(ev: dict) -> str:
    """The verdict an evidence dict holds; one recorded before there were three (only 'verified': true or false, or
    only its sentences) is read from them: verified when it says so (or every sentence is), contradicted when a
    sentence is, else partly checked."""
    if ev.get("status") in VERDICTS:
        return ev["status"]
    said = [st for _, st in ev.get("sentences") or [] if st != "none"]
    if ev.get("verified", bool(said) and all(st == "verified" for st in said)):
        return "verified"
    return "contradicted" if "contradicted" in said else "partly checked"


def evidence(exp: Explanation, narrative, value_text: Callable[[int, int], str] | None = None) -> dict[str, Any]:
    """What a card shows for ``narrative`` of ``exp`` (its state ``narrative.index``; a global summary has no
    state and only its sentences and confidence). ``value_text(i, j)``: state ``i``'s value of feature ``j`` as the
    narratives write it, in its unit ('19.0 % full', not 2.89e+06: :func:`xairl.values.state_value_text` with the
    policy, which the callers have and this layer does not); the card shows it beside the number kept."""
    out: dict[str, Any] = {
        "sentences": [list(s) for s in narrative.sentences],
        "components": {k: v for k, v in narrative.components.items() if v is not None},
        "confidence": narrative.confidence,
        "verified": narrative.verified,
        "status": narrative.status,
        "coverage": narrative.coverage,
        "account": narrative.account,
    }
    i = narrative.index
    if i is None or exp.states is None or exp.values.ndim != 3:
        return out
    c, r = int(exp.chosen[i]), int(exp.runner_up[i])
    deciding = exp.output == "actions" and r != c
    view = exp.values[i, :, c] - exp.values[i, :, r] if deciding else exp.values[i, :, c]
    base = float(exp.base_values[i, c] - (exp.base_values[i, r] if deciding else 0.0))
    labels = exp.value_labels
    rows = []
    for j in np.argsort(-np.abs(view), kind="stable"):
        label = None if labels is None or labels[i, j] is None else str(labels[i, j])
        rows.append(
            {
                "name": exp.feature_names[j],
                "value": label if label is not None else float(exp.states[i, j]),
                **({"value_text": value_text(i, int(j))} if value_text is not None else {}),
                "contribution": float(view[j]),
                "to_chosen": float(exp.values[i, j, c]),
            }
        )
    out.update(
        {
            "action": exp.action_names[c],
            "runner_up": exp.action_names[r] if deciding else None,
            "target": f"margin of {exp.action_names[c]} over {exp.action_names[r]}"
            if deciding
            else f"{exp.action_names[c]}'s score",
            "base": base,
            "output": base + float(view.sum()),
            "features": rows,
        }
    )
    return out


#: what may stand between two sentences of a text besides white space: the bullet that the verifier's split at a line
#: break took off the next sentence (verify._SENTENCE_RE)
_BULLETS = ("", "-", "\u2022", "*")
_BULLET = re.compile(r"([-\u2022*])\s+(?=\S)")


def sentence_lines(text: str, sentences: Iterable) -> list[tuple[int, str, str, str]]:
    """(line breaks before it, its list bullet, sentence, status) per (sentence, status) of ``text``, from the text's
    own separators: a template's list ('Why:\\n- a.\\n- b.') is the sentences 'Why:', 'a.' and 'b.', the last two
    each after one line break and the bullet '-' (a bullet the sentence itself starts with is taken off it: the
    verifier's split at a line break leaves it on a sentence after a full stop). A sentence not found in ``text``
    after the one before it (a text that is not the sentences' own) follows with a space: (0, '', sentence, status).
    """
    out, pos = [], 0
    for s, st in sentences:
        at = text.find(s, pos) if s else -1
        sep = text[pos:at]
        if at < 0 or sep.strip() not in _BULLETS:
            out.append((0, "", s, st))
            continue
        pos = at + len(s)
        breaks, bullet = sep.count("\n") if out else 0, sep.rsplit("\n", 1)[-1].strip()
        own = _BULLET.match(s) if (breaks or not out) and not bullet else None  # ('a.\\n- b': '- b' is one sentence)
        out.append((breaks, own.group(1) if own else bullet, s[own.end() :] if own else s, st))
    return out


def lines_html(text: str) -> str:
    """``text`` escaped, its line breaks as <br>."""
    return "<br>".join(html.escape(line) for line in text.splitlines())


def _num(x) -> str:
    return html.escape(x) if isinstance(x, str) else f"{x:.4g}"


def waterfall_html(ev: dict) -> str:
    """The margin (or score) built from its base, one bar per large contribution: an HTML/CSS waterfall."""
    rows = ev["features"][:SHOWN]
    rest = sum(f["contribution"] for f in ev["features"][SHOWN:])
    steps = [(f["name"], f["contribution"]) for f in rows] + (
        [(f"{len(ev['features']) - SHOWN} others", rest)] if len(ev["features"]) > SHOWN else []
    )
    level, points = ev["base"], [ev["base"]]
    for _, v in steps:
        level += v
        points.append(level)
    lo, hi = min(points), max(points)
    span = (hi - lo) or 1.0
    bars, level = [], ev["base"]
    for name, v in steps:
        a, b = sorted((level, level + v))
        left, width = 100 * (a - lo) / span, max(100 * (b - a) / span, 0.3)
        cls = "up" if v >= 0 else "down"
        bars.append(
            f"<div class=wf-row><span class=wf-name>{html.escape(name)}</span><span class=wf-track>"
            f"<span class='wf-bar {cls}' style='left:{left:.2f}%;width:{width:.2f}%'></span></span>"
            f"<span class=wf-val>{v:+.3g}</span></div>"
        )
        level += v
    return (
        f"<div class=waterfall><div class=wf-head>{html.escape(ev['target'])}: base {ev['base']:.3g} &rarr; "
        f"{ev['output']:.3g}</div>{''.join(bars)}</div>"
    )


def card_html(narrative_text: str, ev: dict, meta: str = "", controls: str = "") -> str:
    """A decision card: the narrative with each sentence marked, the state, the waterfall, the confidence. The
    text's line breaks (a template's list) are <br> between the sentences, with the list's bullets."""
    sentences = ev.get("sentences") or [[narrative_text, "verified" if ev.get("verified") else "unchecked"]]
    text = ""
    for breaks, bullet, s, st in sentence_lines(narrative_text, sentences):
        sep = "<br>" * min(breaks, 2) if breaks else " " if text else ""
        text += (
            f"{sep}{html.escape(bullet) + ' ' if bullet else ''}<span class='s {st}' title='{st}'>{lines_html(s)} "
            f"<sup>{STATUS_MARK.get(st, '?')}</sup></span>"
        )
    comps = "".join(f"<tr><td>{html.escape(k)}</td><td>{v:.2f}</td></tr>" for k, v in ev.get("components", {}).items())
    parts = [f"<p class=narrative>{text}</p>", verdict_html(ev)]
    if meta:
        parts.append(f"<p class=meta>{meta}</p>")
    if ev.get("counterfactual"):  # what would have changed it (xairl.counterfactuals.show.summary)
        parts.append(counterfactual_html(ev["counterfactual"]))
    side = [f"<table class=comp><tr><th>confidence</th><th>{ev.get('confidence', 0):.2f}</th></tr>{comps}</table>"]
    if "features" in ev:
        state = "".join(
            f"<tr><td>{html.escape(f['name'])}</td><td>{_num(f.get('value_text') or f['value'])}</td>"
            f"<td>{f['contribution']:+.3g}</td></tr>"
            for f in ev["features"]
        )
        side.insert(
            0,
            f"<table class=state><tr><th>feature</th><th>value</th><th>to the {'margin' if ev.get('runner_up') else 'score'}"
            f"</th></tr>{state}</table>",
        )
        parts.append(waterfall_html(ev))
    parts.append(f"<div class=side>{''.join(side)}</div>")
    return f"<div class=card>{''.join(parts)}{controls}</div>"


def verdict_html(ev: dict) -> str:
    """The verdict line under a card's narrative: the verdict (with the coverage when partly checked) and the account
    of the margin (what the narrative's features account for, what it leaves out)."""
    status = verdict_of(ev)
    words = html.escape(verdict_text(status, ev.get("coverage")))
    account = f" &middot; {html.escape(ev['account'])}" if ev.get("account") else ""
    return f"<p class='check {status.split()[0]}'>verdict: <b>{words}</b>{account}</p>"


CARD_STYLE = (
    ".card{border:1px solid #ccd;border-radius:6px;padding:.6em 1em;margin:1em 0}.narrative{font-size:105%}"
    ".s.verified sup{color:#070}.s.contradicted{background:#fdd}.s.contradicted sup{color:#b00}"
    ".s.unchecked{background:#ffe9b3}.s.unchecked sup{color:#a60}.side{display:flex;gap:2em;flex-wrap:wrap;"
    "align-items:flex-start}.side table{font-size:85%}.waterfall{margin:.5em 0;font-size:85%;max-width:760px}"
    ".wf-row{display:flex;align-items:center;height:1.4em}.wf-name{width:14em;overflow:hidden;"
    "white-space:nowrap}.wf-track{position:relative;flex:1;height:1em;background:#f4f4f4}.wf-bar{position:"
    "absolute;top:0;height:100%}.wf-bar.up{background:#d62728}.wf-bar.down{background:#1f77b4}"
    ".wf-val{width:5em;text-align:right}.wf-head{font-weight:bold;margin-bottom:.2em}"
    ".meta{color:#555;font-size:90%}.check{font-size:90%;margin:.2em 0}.check.verified b{color:#070}"
    ".check.contradicted b{color:#b00}.check.partly b{color:#a60}" + CF_STYLE
)
