"""What counts as another decision, and which features to try first.

:class:`Goal` reads a target as a *gap* per changed state, positive exactly when the policy decides otherwise there:
for a target action, its score minus the best other available action's (so it is the action the policy takes); for
"any" other action, the best other available score minus the chosen action's; for a :class:`Threshold`, the
output's distance past it. Unavailable actions (the policy's action mask, evaluated on the changed state) score
-inf, so an action the change makes unavailable never counts.

:func:`pushes` ranks the features by how much they push the margin the change must overturn (the chosen action's
score minus the target's, or the output itself), from an explanation of the states (a given one, or
:func:`xairl.explain` with its default method, or integrated gradients for a module deep_shap cannot walk); an
image's regions sum their pixels' contributions.
"""

from __future__ import annotations

import numpy as np

from xairl.counterfactuals.bounds import Units
from xairl.counterfactuals.result import Threshold
from xairl.errors import InputError, UnsupportedModelError
from xairl.explanations.explanation import Explanation
from xairl.policies.policy import Policy

#: background states an explanation is measured against when the search computes one
EXPLAIN_BACKGROUND = 100
#: how far past the line (relative to the scores' size) the search keeps: a re-run in another batch, whose float32
#: sums may round differently, still decides the same
TOLERANCE = 1e-4
#: a flip by less than this share of the scores' size is noise: a float32 network's scores differ in their last bits
#: between batch shapes, so a re-run of one row could read it either way; no counterfactual that near is returned
NOISE = 1e-5


class Goal:
    """What a changed state must do, per state: a gap positive exactly when it decides otherwise."""

    def __init__(self, policy: Policy, xs: np.ndarray, target, rows: np.ndarray | None = None) -> None:
        """``xs``: the states searched (``rows``: their rows among the states given, for a one-line error)."""
        self.policy, self.threshold = policy, target if isinstance(target, Threshold) else None
        scores = policy.scores(xs)
        bad = ~np.isfinite(scores).all(axis=1)
        if bad.any():  # (as explain refuses them: no decision to overturn)
            kind = np.dtype(policy.dtype)
            raise InputError(
                f"the policy's outputs are NaN or infinite for {int(bad.sum())} state(s) searched, first state "
                f"{int(np.argmax(bad) if rows is None else rows[np.argmax(bad)])}: no decision to change; check the states' scale (a {kind.name} network "
                f"overflows beyond ~{np.finfo(kind).max:.0e})."
            )
        m, names = len(xs), policy.action_names
        self.skip = [""] * m  # why a state is not searched ('' where it is)
        if policy.output != "actions":
            self._threshold(policy, scores, target)
            return
        if isinstance(target, Threshold):
            raise InputError("a Threshold targets continuous actions or values; for discrete actions name an action.")
        s = np.where(policy.available(xs), scores, -np.inf)
        order = np.argsort(-s, axis=1, kind="stable")
        self.chosen = order[:, 0]
        runner = (
            np.where(np.isfinite(s[np.arange(m), order[:, 1]]), order[:, 1], -1) if s.shape[1] > 1 else -order[:, 0] - 1
        )
        if target is None:
            self.target = runner
            self.skip = ["no other action is available: there is no runner-up" if r < 0 else "" for r in runner]
        elif isinstance(target, str) and target == "any" and "any" not in names:
            self.target = np.full(m, -1)
        else:
            t = action_index(policy, target)
            self.target = np.full(m, t)
            self.skip = [f"it already chooses {names[t]}" if c == t else "" for c in self.chosen]
        self.compare = np.where(self.target >= 0, self.target, np.maximum(runner, 0))
        self.tol = TOLERANCE * (1 + np.abs(scores[np.arange(m), self.chosen]))
        self.words = [names[t] if t >= 0 else "any other action" for t in self.target]
        self.verb = ["it choose " + (w if t >= 0 else "another action") for w, t in zip(self.words, self.target)]

    def _threshold(self, policy: Policy, scores: np.ndarray, target) -> None:
        if not isinstance(target, Threshold):
            raise InputError(
                f"policy '{policy.name}' outputs {policy.output}: give target=xairl.Threshold("
                f"'{policy.action_names[0]}', above=...) (or below=...) to say what counts as another decision."
            )
        j = action_index(policy, target.output)
        self.j, self.above = j, target.above is not None
        self.bound = float(target.above if self.above else target.below)
        word = f"{policy.action_names[j]} {'above' if self.above else 'below'} {self.bound:g}"
        m = len(scores)
        self.chosen = np.full(m, j)
        verb = f"{policy.action_names[j]} {'rise above' if self.above else 'fall below'} {self.bound:g}"
        self.words, self.verb = [word] * m, [verb] * m
        gap = self.gap(scores, None, np.arange(m))
        self.skip = [f"{word} already (it is {scores[i, j]:.4g})" if gap[i] > 0 else "" for i in range(m)]
        self.compare = self.chosen
        self.tol = np.full(m, TOLERANCE * (1 + abs(self.bound)))

    def gap(self, scores: np.ndarray, avail: np.ndarray | None, who: np.ndarray) -> np.ndarray:
        """(N,) positive exactly where a state with these outputs decides otherwise (state ``who`` of the search)."""
        if self.threshold is not None:
            v = scores[:, self.j]
            return v - self.bound if self.above else self.bound - v
        s = np.where(avail, scores, -np.inf)
        r, t, c = np.arange(len(s)), self.target[who], self.chosen[who]
        pick = np.where(t >= 0, t, c)
        others = s.copy()
        others[r, pick] = -np.inf
        best = others.max(axis=1)
        with np.errstate(invalid="ignore"):
            g = np.where(t >= 0, s[r, pick] - best, best - s[r, pick])
        return np.nan_to_num(g, nan=-np.inf)


def feasible(policy: Policy, x: np.ndarray) -> np.ndarray:
    """``policy.feasible(x)`` checked: a bool (n,) array, or one line naming the callback and what went wrong."""
    try:
        ok = np.asarray(policy.feasible(x))
    except Exception as e:  # (the user's code: whatever it raises is told in one line, not as an internal error)
        first = (str(e).strip().splitlines() or [""])[0]
        raise InputError(
            f"policy '{policy.name}': its feasible callback raised {type(e).__name__}: {first:.200} (on {len(x)} "
            f"state(s) of {x.shape[1]} columns); fix it to return one bool per state."
        ) from None
    if ok.shape != (len(x),) or ok.dtype.kind != "b":
        raise InputError(f"policy '{policy.name}': feasible must return bool ({len(x)},), got {ok.dtype} {ok.shape}.")
    return ok


def action_index(policy: Policy, name) -> int:
    """The output column named (or numbered) ``name``; a one-line error naming the known ones."""
    names = policy.action_names
    if isinstance(name, (int, np.integer)) and not isinstance(name, bool) and -len(names) <= name < len(names):
        return int(name) % len(names)
    if isinstance(name, str):
        if name in names:
            return names.index(name)
        hits = [a for a, aliases in policy.action_aliases.items() if name in aliases and a in names]
        if len(hits) == 1:  # an alias several actions share ('switch cells') names none of them
            return names.index(hits[0])
    what = "action" if policy.output == "actions" else "output"
    extra = ', or "any"' if policy.output == "actions" else ""
    raise InputError(f"{what} {name!r:.40} is unknown; use one of {', '.join(names[:6])}{extra}.")


def lead(scores: np.ndarray, available: np.ndarray, a: int) -> float:
    """Action ``a``'s score minus the best other available action's (-inf where none other is available): how far a
    decision for ``a`` is past the line, the margin a counterfactual reports and its sentence says."""
    others = np.delete(np.where(available, scores, -np.inf), a)
    return float(scores[a] - others.max()) if np.isfinite(others).any() else -np.inf


def of_states(explanation, n: int, rows: np.ndarray) -> Explanation | None:
    """``explanation`` (of all ``n`` states, or of the ``rows`` searched) as the explanation of the rows, in their
    order; None when none was given."""
    if explanation is None:
        return None
    if not isinstance(explanation, Explanation):
        raise InputError(f"explanation is an xairl.Explanation of the states, not {type(explanation).__name__}.")
    if len(explanation) == n:
        return explanation[rows]
    if len(explanation) == len(rows):
        return explanation
    raise InputError(f"the explanation has {len(explanation)} state(s) but {n} were given; explain the same states.")


def pushes(policy: Policy, goal: Goal, units: Units, xs: np.ndarray, bg, exp: Explanation | None) -> np.ndarray:
    """(m, U) each unit's contribution to the margin the change must overturn, for the states ``xs`` (``exp``: their
    explanation, :func:`of_states`; None: computed here)."""
    if exp is None:
        from xairl.attributors import explain

        try:
            exp = explain(policy, xs, bg[:EXPLAIN_BACKGROUND])
        except UnsupportedModelError:  # a module deep_shap cannot walk: gradients along a path take any module
            exp = explain(policy, xs, bg[:EXPLAIN_BACKGROUND], method="integrated_gradients")
    m = np.arange(len(xs))
    v = exp.values
    if goal.threshold is not None:
        c = v[m, :, goal.j]
    else:
        c = v[m, :, goal.chosen] - v[m, :, goal.compare]
    index = {f: j for j, f in enumerate(exp.feature_names)}
    out = np.zeros((len(xs), units.n))
    for u, name in enumerate(units.names):
        cols = [index.get(name)] if name in index else [index.get(policy.feature_names[j]) for j in units.columns[u]]
        if None not in cols:
            out[:, u] = c[:, cols].sum(axis=1)
    return out
