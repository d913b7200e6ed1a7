"""A counterfactual as a fact a template can say (issue 56): 'Had the uplink buffer been below 38 % full (it was
100 % full), the DQN would have chosen to hand over to candidate 2 (margin 4.2).'

How it is built from a search's answer (:class:`xairl.counterfactuals.Counterfactuals`): each change's value is
written as the narratives write values (:func:`xairl.values.value_text`: a buffer in % of its capacity, dBm, a
category's label), and rounded *away from the line*, to the digits it is written with: 'below 37.6' for a line at
37.64, never 'below 37.7', which rounds back across it; nor past a declared bound, and a value at its bound is said
with no direction word ('been -34 dB', not 'below -34 dB' where -34 dB is the floor). The state with the values as
written is then run through the policy (all candidates in one batch, its action mask honoured); the first one that
still takes the search's action is the fact (else the first that takes any other action than the one taken: the
words name what the policy does there), with the action and the margin of that re-run. What a template prints is
therefore exactly what the verifier re-runs (:mod:`xairl.verification.own.counterfactual`). A candidate must
also keep the state one the world allows as written (:func:`broken`: the policy's ``feasible``, the declared bounds,
no immutable feature changed): rounding away from the line may step off the searched point. None of the candidates
flipping as written (a line that bends within one rounding step) leaves the fact out: no sentence rather than a
wrong one.

A window policy's past slot (``speed[t-2]``) is named as that slot, 'the speed 2 steps ago' (:func:`feature_words`),
never by its signal's words alone, which name the current value.
"""

from __future__ import annotations

from dataclasses import dataclass
from dataclasses import replace as _replace

import numpy as np

from xairl.counterfactuals import Counterfactual, Counterfactuals
from xairl.counterfactuals.goals import NOISE, feasible, lead
from xairl.counterfactuals.goals import action_index as resolve  # (the one resolver of an action's name or alias)
from xairl.counterfactuals.show import outward as _outward  # (the one rounding rule: away from the line)
from xairl.counterfactuals.show import summary
from xairl.errors import InputError
from xairl.explanations.explanation import Explanation
from xairl.numbers import format_number
from xairl.policies.policy import FeatureInfo, Policy
from xairl.values import fill_and_text

__all__ = [
    "ChangeFact",
    "CounterfactualFact",
    "action_index",
    "action_words",
    "as_written",
    "broken",
    "counterfactual_fact",
    "feature_words",
    "lead",
    "said_counterfactual",
]

#: extra rounding steps tried, away from the line, when the value as written does not flip the decision
_NUDGES = (0, 1, 3)
#: (NOISE: a flip by less than this share of the scores' size is noise, :mod:`xairl.counterfactuals.goals`; the next
#: nudge is said instead)


@dataclass(frozen=True)
class ChangeFact:
    """One feature's change, as a narrative says it.

    :param name: the feature's name; ``label`` its description (or the name); ``unit`` its unit.
    :param value: its value in the state; ``value_text`` as narratives write it ('100 % full', '-85.3 dBm').
    :param after: the value it would need, as written (rounded away from the line), in the feature's own unit;
        ``after_text`` written like ``value_text`` ('37.6 % full'). Print ``after_text``: for a feature with a capacity
        ``after`` is in its unit (bits), and ``|num`` may round it back across the line.
    :param direction: 'below' (the value would have to be lower) or 'above'; '' for a category ('been <label>').
    :param fill: for a feature with a capacity, ``value`` and ``after`` in % of it (``after_fill``); else None.
    """

    name: str
    label: str
    unit: str
    value: float
    value_text: str
    after: float
    after_text: str
    direction: str
    fill: float | None = None
    after_fill: float | None = None


@dataclass(frozen=True)
class CounterfactualFact:
    """What would have changed a decision, or that nothing within the bounds would have.

    :param reachable: False when no change of at most ``max_changes`` features within the bounds flips it
        (``changes`` is then empty, ``reason`` says why).
    :param changes: the changes, all together, largest push first.
    :param action: the action the policy takes with the changes as written; ``action_words`` the same as a text
        says it (its first alias, e.g. 'hand over to candidate 2', else its name); '' when unreachable.
    :param margin: that action's score minus the best other available action's, with the changes as written.
    :param chosen: the action taken in the state; ``target`` what was asked ('the runner-up', a named action).
    """

    reachable: bool
    changes: tuple[ChangeFact, ...]
    action: str
    action_words: str
    margin: float
    chosen: str
    target: str
    max_changes: int
    reason: str = ""


def _written(before: float, after: float, info: FeatureInfo, extra: int) -> tuple[float, float | None, str]:
    """(the value as written in the feature's unit, its fill or None, its text) for a change to ``after``."""
    if info.categories:
        code = int(np.clip(round(after), 0, len(info.categories) - 1))
        return float(code), None, info.categories[code]
    down = after < before
    if info.capacity is not None:
        fill = float(np.clip(_outward(100.0 * after / info.capacity, down, extra), 0.0, 100.0))  # (never -0.1 % full)
        raw = fill * info.capacity / 100.0
        return raw, fill, fill_and_text(raw, info, None)[1]
    raw = _outward(after, down, extra)
    if info.bounds is not None:  # rounded away from the line, never past a declared bound: at it ('been -34 dB')
        raw = float(np.clip(raw, *info.bounds))
    return raw, None, fill_and_text(raw, info, None)[1]


def action_index(policy: Policy, text: str) -> int | None:
    """The action ``text`` names (its name, or an alias no other action has), else None: the search's resolver."""
    try:
        return resolve(policy, text.strip())
    except InputError:
        return None


def feature_words(policy: Policy, name: str) -> str:
    """How a counterfactual names a feature: its description, else its name; a window's past slot
    (``speed[t-2]``, :meth:`xairl.policies.windows.Window.names`) as its signal's words that many steps ago ('the speed 2
    steps ago')."""
    info = policy.features.get(name) or FeatureInfo()
    window = policy.observation.parts[0].window if policy.observation.kind == "window" else None
    slots = window.names() if window is not None else []
    if name in slots:
        at = slots.index(name)
        back, signal = window.steps - 1 - at // len(window.signals), window.signals[at % len(window.signals)]
        if back:
            return f"{info.description or signal} {back} step{'s' if back > 1 else ''} ago"
    return info.description or name


def broken(policy: Policy, states: np.ndarray, changed: list[list[int]]) -> list[str]:
    """Per changed state (``states`` (n, F), row r with columns ``changed[r]`` changed): '' when the world allows
    it, else which constraint it breaks (an immutable feature changed, a declared bound crossed, the policy's
    ``feasible`` false), in words."""
    ok = np.ones(len(states), bool) if policy.feasible is None else feasible(policy, np.asarray(states))
    out = []
    for r, cols in enumerate(changed):
        why = "" if ok[r] else f"policy '{policy.name}' calls that state infeasible (its feasible() is False)"
        for j in cols:
            f = policy.feature_names[j]
            info, v = policy.features.get(f) or FeatureInfo(), float(states[r, j])
            if info.immutable or info.kind == "identifier":
                why = f"{f} is declared immutable: no counterfactual changes it"
            elif info.bounds is not None and not info.bounds[0] <= v <= info.bounds[1]:
                why = f"{f} = {v:.6g} is outside its declared bounds {info.bounds}"
        out.append(why)
    return out


def action_words(policy: Policy, action: str) -> str:
    """An action as a text says it: its first alias that names no other action, else its name."""
    taken = [a for n, al in policy.action_aliases.items() if n != action for a in al]
    return next((a for a in policy.action_aliases.get(action, ()) if a not in taken), action)


def _unreachable(found: Counterfactuals, max_changes: int, reason: str = "") -> CounterfactualFact:
    return CounterfactualFact(False, (), "", "", float("nan"), found.chosen, found.target, max_changes, reason)


def counterfactual_fact(
    exp: Explanation, index: int, policy: Policy, found: Counterfactuals, max_changes: int = 2
) -> CounterfactualFact | None:
    """The fact of ``found`` (the search's answer for state ``index``): its counterfactuals written as a narrative
    writes them, re-run through ``policy`` in one batch; the first that flips as written to the search's action,
    else the first that flips to another action than the chosen one (its words name the action taken), else None
    (module doc)."""
    if policy.output != "actions" or exp.states is None or exp.states.shape[1] != policy.n_features:
        raise InputError("counterfactual words are for discrete actions on flat states; use xairl.counterfactual().")
    if found.index != index:
        raise InputError(f"the counterfactuals given are of state {found.index}, not {index}; search state {index}.")
    if not found.reachable:
        return _unreachable(found, max_changes, found.reason)
    unknown = {c.feature for cf in found.found for c in cf.changes} - set(policy.feature_names)
    if unknown:  # (an image's regions: their change is every pixel of them shifted, which no sentence states yet)
        raise InputError(f"counterfactual words name the policy's features; {sorted(unknown)[0]!r} is none of them.")
    picks = [p for p in _picks(policy, np.asarray(exp.states[index], dtype=float), found) if p is not None]
    # the search's own action as written first; else another action than the chosen one, which the words then name
    pick = next((p for p in picks if p[2] == p[0].action), picks[0] if picks else None)
    if pick is None:
        return None
    _, changes, act, margin, _ = pick
    words = action_words(policy, act)
    return CounterfactualFact(True, changes, act, words, margin, found.chosen, found.target, max_changes)


def _picks(policy: Policy, state: np.ndarray, found: Counterfactuals) -> list[tuple | None]:
    """Per counterfactual of ``found``: (it, its changes as written, the action taken then, its margin, its score) for
    the first rounding (of :data:`_NUDGES`) that, re-run as written, flips the decision to the search's action, else
    to another than the one chosen, within the world's constraints and past the noise; None when none does. One
    batch."""
    said = [(k, _said(policy, state, cf.changes, extra)) for k, cf in enumerate(found.found) for extra in _NUDGES]
    said = [(k, changes) for k, changes in said if changes]
    out: list[tuple | None] = [None] * len(found.found)
    if not said:
        return out
    rows = np.repeat(state[None], len(said), axis=0)
    cols = [[policy.feature_names.index(c.name) for c in changes] for _, changes in said]
    for n, (_, changes) in enumerate(said):
        rows[n, cols[n]] = [c.after for c in changes]
    scores, avail = policy.scores(rows), policy.available(rows)
    free, chosen = np.where(avail, scores, -np.inf), policy.action_names.index(found.chosen)
    breaks = broken(policy, rows, cols)
    for n, (k, changes) in enumerate(said):
        a = int(free[n].argmax())
        margin = lead(scores[n], avail[n], a)
        if a == chosen or breaks[n] or margin <= NOISE * max(1.0, np.abs(scores[n]).max()):
            continue
        own = policy.action_names[a] == found.found[k].action
        if out[k] is None or (own and out[k][2] != found.found[k].action):
            out[k] = (found.found[k], changes, policy.action_names[a], margin, float(scores[n, a]))
    return out


def as_written(policy: Policy, found: Counterfactuals, text=None, n: int = 3) -> dict:
    """What the CLI and the report's cards show of ``found``: :func:`xairl.counterfactuals.show.summary` of its
    counterfactuals as the words write them, each re-run through ``policy`` as written (the one that the sentence
    says first among them, :func:`_picks`); one that flips as found but not as written is left out, a change that
    the written digits do not show ('0 bit -> 0 bit') is no change, and one the same as written as another is left
    out."""
    if not found.found or policy.output != "actions":
        return summary(found, text, n, as_written=policy.output == "actions")
    cf0 = found.found[0]
    state = np.asarray(cf0.state, dtype=float).copy()
    for c in cf0.changes:  # (the state searched: the changed one with its changes undone)
        state[policy.feature_names.index(c.feature)] = c.before
    shown = []
    for cf, changes, act, margin, output in (p for p in _picks(policy, state, found) if p is not None):
        x, after = state.copy(), {c.name: c.after for c in changes}
        x[[policy.feature_names.index(f) for f in after]] = list(after.values())
        kept = tuple(_replace(c, after=float(after[c.feature])) for c in cf.changes if c.feature in after)
        if any(kept == other.changes for other in shown):
            continue  # (the same change as written as one shown: a no-op change left out)
        shown.append(Counterfactual(kept, x, act, output, margin, cf.distance, cf.distance_scaled))
    reason = found.reason or ("" if shown else "the search's changes flip it, but none as written: the line bends "
                              "within one written digit of them")  # fmt: skip
    return summary(Counterfactuals(found.index, found.chosen, found.target, tuple(shown), reason), text, n, True)


def _said(policy: Policy, state: np.ndarray, changes, extra: int) -> tuple[ChangeFact, ...]:
    """The changes as written, ``extra`` rounding steps further from the line."""
    out = []
    for c in changes:
        j, info = policy.feature_names.index(c.feature), policy.features.get(c.feature) or FeatureInfo()
        before = float(state[j])
        raw, fill, text = _written(before, float(c.after), info, extra)
        was, was_text = fill_and_text(before, info, _label(info, before))
        if _shown(raw, info) == _shown(before, info):
            continue  # no change in the digits written ('0 % full (it was 0 % full)'): left out, and not re-run
        # no direction word for a category, nor at a capacity's end ('been 100 % full', not 'above 100 % full'), nor
        # at a declared bound ('been -34 dB', not 'below -34 dB' where -34 dB is the floor)
        end = fill in (0.0, 100.0) or (info.bounds is not None and raw in info.bounds)
        direction = "" if info.categories or end else "below" if raw < before else "above"
        label = feature_words(policy, c.feature)
        out.append(ChangeFact(c.feature, label, info.unit, before, was_text, raw, text, direction, was, fill))
    return tuple(out)


def said_counterfactual(
    exp: Explanation, index: int | None, policy: Policy | None, ask, background=None, max_changes: int = 2
) -> CounterfactualFact | None:
    """The counterfactual fact of decision ``index``, or None when not asked: ``ask`` is False (or None), True (run
    the search, :func:`xairl.counterfactuals.search.counterfactual`, guided by ``exp``), the search's answer
    (:class:`~xairl.counterfactuals.Counterfactuals`) for that state, or its answers for several states (a tuple,
    ``index=None``), among which that state's is taken. Anything else is refused in one line."""
    many = isinstance(ask, (tuple, list)) and ask and all(isinstance(a, Counterfactuals) for a in ask)
    if ask is None or ask is False:
        return None
    if ask is not True and not many and not isinstance(ask, Counterfactuals):
        raise InputError(
            f"counterfactual is True (search), False, or xairl.counterfactual()'s answer; got {ask!r:.40}."
        )
    if index is None:
        raise InputError("a counterfactual is of one decision: give narrate a state index, not index=None.")
    if policy is None:
        raise InputError("counterfactual=True needs the policy (policy=...): the search and its check run it.")
    if policy.output != "actions":
        raise InputError(
            f"counterfactual words are for discrete actions; policy '{policy.name}' outputs {policy.output}: narrate "
            "without counterfactual=, and call xairl.counterfactual(..., target=xairl.Threshold(...)) for it."
        )
    if many:
        ask = next((a for a in ask if a.index == index), None) or _refuse(index)  # a batch answer (index=None)
    if ask is True:
        from xairl.counterfactuals.search import counterfactual

        ask = counterfactual(  # (three, so that one still flips once its values are rounded away from the line)
            policy, exp.states, index=index, background=background, explanation=exp, max_changes=max_changes, n=3
        )
    return counterfactual_fact(exp, index, policy, ask, max_changes)


def _shown(value: float, info: FeatureInfo) -> float:
    """A value as its text shows it: a category's code, else the number written (a fill in % of a capacity)."""
    if info.categories:
        return float(round(value))
    return float(format_number(100.0 * value / info.capacity if info.capacity is not None else value))


def _refuse(index: int):
    raise InputError(f"the counterfactuals given have no answer for state {index}; search it (counterfactual=True).")


def _label(info: FeatureInfo, value: float) -> str | None:
    code = int(round(value))
    return info.categories[code] if info.categories and 0 <= code < len(info.categories) else None
