"""The counterfactual search: the smallest change of at most two features that makes the policy decide otherwise,
found by running the policy, never estimated.

For each decision:

1. **What counts as another decision.** Discrete actions: the runner-up (the second-best available action) taking
   over, a named action, or ``"any"`` other action; the action mask holds in the changed state, so an action that
   becomes unavailable is no flip. Continuous actions and values: a :class:`Threshold` crossed by one output. Each is
   read as a *gap*, positive exactly when the changed state decides otherwise (the target's score minus the best
   other available one; the output's distance past the threshold); a state the policy's ``feasible`` rejects has no
   positive gap.
2. **Which units first.** The units that may change (:mod:`xairl.counterfactuals.bounds`) are ranked by the size of
   their contribution to the margin the change must overturn (``explanation`` if given, else
   :func:`xairl.explain` with its default method, once for all the states).
3. **Single changes.** For the top units, a grid of 64 values (32 for an image) across each one's range is run
   through the policy in one batched pass; the flipping value nearest the state (in background quantiles) is kept
   and the crossing between it and its non-flipping neighbour refined by bisection (24 halvings), batched across
   units and states, so that the value returned is just past the line: by a gap of 1e-4 x (1 + |the chosen score|)
   (or of the threshold), so that a re-run in another batch, whose float32 sums may round differently, decides the
   same.
4. **Pairs**, among the top 9 units: a 41x41 grid per pair over both ranges, zoomed in three times around the nearest
   flipping cell (a 13x13 grid over the cells beside it), then bisection along the line from the state to it. A
   pair may be nearer than the nearest single change, so a narrow state's pairs are always searched; an image's
   (its top 4 regions, 13x13 grids: each pair costs hundreds of passes over the image) only where no single change
   flips, or when ``n > 1``. A pair no nearer than one of its features changed alone, or one of whose changes moves
   nothing, is dropped. A grid can miss a flip between its points: "none found" is the search's answer, no proof.
5. **Checked.** The candidates, ranked by distance in quantiles (ties by the scaled distance), one per set of
   features, are run through the policy once more, all in one batch; one that does not flip (or is infeasible, or
   out of range) is dropped. What is returned is exactly what was run. Nor is any state a flip whose scores are not
   finite (a float32 network overflowing near its largest number: the same state alone may score finitely and keep
   its action), whose flip is within float32's noise at its scores' size (:data:`~.goals.NOISE`), or after which the
   mask allows a single action (no other allowed action for a margin to be over).

Windows (a memory policy's slots) are searched as flat features, each slot on its own, the newest step's only unless
``past`` (:mod:`xairl.counterfactuals.bounds`); a binary feature only whole. The decisions are searched
:data:`CHUNK` at a time, so memory does not grow with the batch. ``max_changes`` is 1 or 2.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

from xairl.counterfactuals import bounds
from xairl.counterfactuals.goals import NOISE, Goal, feasible, lead, of_states, pushes
from xairl.counterfactuals.result import Change, Counterfactual, Counterfactuals
from xairl.errors import InputError
from xairl.policies.policy import Policy

GRID, GRID2, TOP_SINGLE, TOP_PAIR, STEPS, ZOOMS = 64, 13, 16, 9, 24, 3
#: the first grid over a pair of a narrow state (41 x 41: a 13 x 13 one missed a flip of one UAV decision in seven
#: that a brute force found, issue 56's review); the zooms use GRID2
COARSE = 41
#: a state of more flat columns than this (an image) pairs only its top 4 units on GRID2 grids (each pair costs 676
#: forward passes of the network over the whole image) and searches single changes on a grid of GRID_WIDE
WIDE, TOP_PAIR_WIDE, GRID_WIDE = 1024, 4, 32
_BACKGROUND = 200  # states drawn from the policy's sampler when no background is given
#: decisions searched at a time: a narrow state's pair grids take about 1 MB a decision, so a batch of any size
#: stays within a few hundred MB (20,000 toy states at once needed 23 GB, issue 64)
CHUNK = 64


def counterfactual(
    policy: Policy,
    states,
    index: int | None = 0,
    target=None,
    features=None,
    max_changes: int = 2,
    background=None,
    explanation=None,
    n: int = 1,
    past: bool = False,
) -> Counterfactuals | tuple[Counterfactuals, ...]:
    """What would have had to differ for ``policy`` to decide otherwise on ``states[index]``.

    :param index: the decision's row; None: every state, batched (a tuple of results, one per state).
    :param target: discrete actions: None (the runner-up), an action's name or index, or "any" (any other action);
        continuous actions and values: a :class:`Threshold` on an output.
    :param features: only these may change (names; a group's name stands for its members).
    :param max_changes: at most this many features change (1 or 2).
    :param background: typical states (default: the policy's sampler): the ranges and the quantiles.
    :param explanation: an :class:`xairl.Explanation` of ``states`` (or of the one state) to rank the features by.
    :param n: how many counterfactuals to return, each changing a different set of features.
    :param past: a window policy: change its past observations' slots too (default: only the newest step's).
    """
    x = policy.check_states(states)
    rows = _rows(index, len(x))
    if isinstance(max_changes, bool) or not isinstance(max_changes, (int, np.integer)) or max_changes not in (1, 2):
        raise InputError(f"max_changes is 1 or 2 (changes of more features are not searched); got {max_changes!r:.40}.")
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise InputError(f"n is how many counterfactuals to return per decision, a whole number >= 1; got {n!r:.40}.")
    bg = policy.background(_BACKGROUND) if background is None else policy.check_states(background, "background")
    units = bounds.units(policy, bg, features, past)
    exp = of_states(explanation, len(x), rows)
    out: list[Counterfactuals] = []
    for start in range(0, len(rows), CHUNK):  # (memory: a chunk's grids at a time, never every decision's)
        part = rows[start : start + CHUNK]
        goal = Goal(policy, x[part], target, part)
        found = _Search(policy, x[part], units, goal)
        chunk = None if exp is None else exp[start : start + CHUNK]
        found.rank(pushes(policy, goal, units, x[part], bg, chunk) if units.n else None)
        found.run(max_changes, int(n))
        out += [found.result(k, int(r), max_changes) for k, r in enumerate(part)]
    return tuple(out) if index is None else out[0]


class _Search:
    """The candidates of each state, searched in batches across units and states."""

    def __init__(self, policy: Policy, xs: np.ndarray, units: bounds.Units, goal: Goal) -> None:
        self.policy, self.xs, self.units, self.goal = policy, xs, units, goal
        self.own = units.values(xs)
        self.low, self.high = units.ranges(self.own)
        self.scale = units.scale()
        self.evals = np.zeros(len(xs), dtype=np.int64)
        self.candidates: list[dict[tuple[int, ...], tuple[float, ...]]] = [{} for _ in xs]
        self.active = np.array([not s for s in goal.skip]) & (units.n > 0)
        self.checked: list[list[Counterfactual]] = [[] for _ in xs]
        # an image's regions (or a very wide state): each change costs a pass over the whole image (issue 64: a
        # 1x32x32 image, 1,024 columns, took the narrow path's 41x41 pair grids, 79,857 passes a decision)
        self.wide = units.regions or xs.shape[1] > WIDE

    def rank(self, contributions: np.ndarray | None) -> None:
        """Order each state's units by |contribution| (``contributions`` (m, U) or None: as they come)."""
        push = np.zeros((len(self.xs), self.units.n)) if contributions is None else np.abs(contributions)
        self.push = push
        self.order = np.argsort(-push, axis=1, kind="stable")

    def gaps(self, who: np.ndarray, unit: np.ndarray, delta: np.ndarray) -> np.ndarray:
        """The gap of each state ``xs[who]`` with units ``unit`` (N, k) shifted by ``delta`` (N, k), in batches."""
        f = self.xs.shape[1]
        step = max(64, 2**21 // f)
        gap = np.empty(len(who))
        for s in range(0, len(who), step):
            sl = slice(s, s + step)
            x = self.xs[who[sl]].astype(np.float64)
            for k in range(unit.shape[1]):
                self.units.shift(x, unit[sl, k], delta[sl, k])
            gap[sl] = self._gap(x.astype(self.policy.dtype), who[sl])[0]
        np.add.at(self.evals, who, 1)
        gap -= self.goal.tol[who]  # the search keeps clear of the line by more than float32's rounding
        return gap

    def _gap(self, x: np.ndarray, who: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The gap of each state ``x`` (no flip where a score is not finite, where the mask leaves one action: no
        margin to report, or where ``feasible`` says no), and its scores."""
        p = self.policy
        scores = p.scores(x)
        avail = p.available(x) if p.output == "actions" else None
        g = self.goal.gap(scores, avail, who)
        # a score that overflowed (a float32 network given values near its largest number) decides nothing: the same
        # state alone may score finitely and keep its action (issue 64)
        bad = ~np.isfinite(scores).all(axis=1) | (avail.sum(axis=1) < 2 if avail is not None else False)
        g = np.where(bad, -np.inf, g)
        if p.feasible is not None:
            g = np.where(feasible(p, x), g, -np.inf)
        return g, scores

    def run(self, max_changes: int, n: int) -> None:
        self.singles()
        if max_changes >= 2:
            # a narrow state's pairs always (a pair may be nearer than the nearest single change: DiCE found one);
            # an image's only where no single change flips (each pair costs hundreds of passes over the image)
            narrow = self.xs.shape[1] <= WIDE
            need = self.active & (np.array([not c for c in self.candidates]) | (n > 1) | narrow)
            self.pairs(np.flatnonzero(need))
        self.check(n)

    def _distance(self, units: np.ndarray, values: np.ndarray, who: np.ndarray) -> np.ndarray:
        """Quantile distance of units (.., k) of states ``who`` moved to ``values`` (.., k), summed over k, plus a
        tie-break by the scaled distance far below any quantile step."""
        own = self.own[who[..., None], units]
        q = np.abs(self.units.quantile(values, units) - self.units.quantile(own, units)).sum(axis=-1)
        return q + 1e-9 * (np.abs(values - own) / self.scale[units]).sum(axis=-1)

    def singles(self) -> None:
        """One unit each: a grid across its range, the nearest flip, then the crossing refined by bisection."""
        who = np.flatnonzero(self.active)
        if not len(who):
            return
        k, size = min(TOP_SINGLE, self.units.n), GRID_WIDE if self.wide else GRID
        top = self.order[who, :k]
        lo, hi, own = (a[who[:, None], top] for a in (self.low, self.high, self.own))
        grid = lo[..., None] + (hi - lo)[..., None] * np.linspace(0.0, 1.0, size)  # (m, k, G)
        w = np.broadcast_to(who[:, None, None], grid.shape)
        u = np.broadcast_to(top[..., None], grid.shape)
        grid = self.units.snap(grid, u)  # (a binary unit's grid: its two values)
        good = self.gaps(w.ravel(), u.reshape(-1, 1), (grid - own[..., None]).reshape(-1, 1)).reshape(grid.shape) > 0
        key = np.where(good, self._distance(u[..., None], grid[..., None], w), np.inf)
        g = key.argmin(axis=-1)
        has = np.isfinite(key.min(axis=-1))
        at = np.take_along_axis(grid, g[..., None], -1)[..., 0]
        up = at > own  # the grid's neighbour on the state's side of the flip never flips (it is nearer)
        side = np.take_along_axis(grid, np.clip(g + np.where(up, -1, 1), 0, size - 1)[..., None], -1)[..., 0]
        inner = np.where(up, np.where(side > own, side, own), np.where(side < own, side, own))
        i, j = np.nonzero(has)
        done = self._bisect(who[i], top[i, j][:, None], own[i, j][:, None], inner[i, j][:, None], at[i, j][:, None])
        done = np.where(self.units.binary[top[i, j]][:, None], at[i, j][:, None], done)  # (whole: no bisection)
        for s, unit, value in zip(who[i], top[i, j], done[:, 0]):
            self.candidates[s][(int(unit),)] = (float(value),)

    def _bisect(self, who, unit, own, bad, good) -> np.ndarray:
        """Values (N, k) just past the line between ``bad`` (no flip) and ``good`` (a flip), along the segment."""
        bad, good = bad.astype(np.float64), good.astype(np.float64)
        for _ in range(STEPS):
            mid = (bad + good) / 2
            ok = self.gaps(who, unit, mid - own) > 0
            good = np.where(ok[:, None], mid, good)
            bad = np.where(ok[:, None], bad, mid)
        return good

    def pairs(self, who: np.ndarray) -> None:
        """Two units each, among the top ones: a 2-D grid over both ranges, zoomed in around the nearest flipping
        cell, then bisection along the line from the state to it."""
        wide = self.wide
        k = min(TOP_PAIR_WIDE if wide else TOP_PAIR, self.units.n)
        if not len(who) or k < 2:
            return
        combos = np.array(list(combinations(range(k), 2)))
        units = self.order[who, :k][:, combos].reshape(-1, 2)  # (P, 2): every pair of every state
        w = np.repeat(who, len(combos))
        lo, hi, own = (a[w[:, None], units] for a in (self.low, self.high, self.own))
        size = GRID2 if wide else COARSE
        best, has = self._grid2(w, units, own, lo, hi, np.full(len(w), False), np.zeros((len(w), 2)), size)
        for _ in range(
            ZOOMS
        ):  # (each zoom's box: a GRID2 grid's cells either side of the best, however fine the first)
            step = (hi - lo) / (GRID2 - 1)
            lo, hi = np.maximum(lo, best - step), np.minimum(hi, best + step)
            best, has = self._grid2(w, units, own, lo, hi, has, best)
        # a binary unit stays at its flipped value along the ray (only the other one is bisected: never a fraction)
        start = np.where(self.units.binary[units], best, own)
        done = self._ray(w[has], units[has], own[has], start[has], best[has])
        for s, us, vs in zip(w[has], units[has], done):
            self.candidates[s][tuple(int(u) for u in us)] = tuple(float(v) for v in vs)

    def _grid2(self, w, units, own, lo, hi, had, best, size=GRID2) -> tuple[np.ndarray, np.ndarray]:
        """The nearest flipping point of a ``size`` x ``size`` grid over each box [lo, hi] (P, 2) and whether there is
        one (where none is, ``best`` and ``had`` as they were)."""
        lin = np.linspace(0.0, 1.0, size)
        axes = lo[:, :, None] + (hi - lo)[:, :, None] * lin  # (P, 2, G)
        axes = self.units.snap(axes, np.broadcast_to(units[:, :, None], axes.shape))
        shape = (len(w), size, size)
        values = np.stack(
            [np.broadcast_to(axes[:, 0, :, None], shape), np.broadcast_to(axes[:, 1, None, :], shape)], -1
        )
        us = np.broadcast_to(units[:, None, None, :], values.shape)
        ws = np.broadcast_to(w[:, None, None], shape)
        good = self.gaps(ws.ravel(), us.reshape(-1, 2), (values - own[:, None, None, :]).reshape(-1, 2)) > 0
        # the distance of each cell: its two axes' terms, each computed once per axis value (a grid's quantiles are
        # separable: 41 times fewer than per cell), summed in the order _distance sums them
        q = np.abs(self.units.quantile(axes, np.broadcast_to(units[:, :, None], axes.shape)) - self._q_own(w, units))
        sc = np.abs(axes - own[:, :, None]) / self.scale[units][:, :, None]
        dist = (q[:, 0, :, None] + q[:, 1, None, :]) + 1e-9 * (sc[:, 0, :, None] + sc[:, 1, None, :])
        key = np.where(good.reshape(shape), dist, np.inf).reshape(len(w), -1)
        cell = key.argmin(axis=-1)
        has = np.isfinite(key[np.arange(len(w)), cell])
        found = values.reshape(len(w), -1, 2)[np.arange(len(w)), cell]
        return np.where(has[:, None], found, best), has | had

    def _q_own(self, w: np.ndarray, units: np.ndarray) -> np.ndarray:
        """(P, 2, 1) the background quantile of each state's own value of each unit of its pair."""
        return self.units.quantile(self.own[w[:, None], units], units)[:, :, None]

    def _ray(self, who, unit, own, start, end) -> np.ndarray:
        """Points just past the line on the segments from ``start`` (no flip) to ``end`` (a flip), (N, k); ``own``
        the state's values."""
        bad, good = np.zeros(len(who)), np.ones(len(who))
        for _ in range(STEPS):
            mid = (bad + good) / 2
            ok = self.gaps(who, unit, start - own + mid[:, None] * (end - start)) > 0
            good, bad = np.where(ok, mid, good), np.where(ok, bad, mid)
        return start + good[:, None] * (end - start)

    def check(self, n: int) -> None:
        """Run the best candidates of every state once more, as the states they are returned as; keep the first
        ``n`` that flip, are feasible and lie within the ranges."""
        picks = []
        for s, found in enumerate(self.candidates):
            sizes = {units: self._sizes(s, units, values) for units, values in found.items()}
            # a pair no nearer than one of its features alone is that single change with a needless extra one, and so
            # is a pair one of whose changes moves nothing
            kept = [
                k
                for k in found
                if len(k) == 1
                or (
                    all(sizes.get((u,), (np.inf,)) > sizes[k] for u in k)
                    and all(abs(v - self.own[s, u]) > 1e-9 * self.scale[u] for u, v in zip(k, found[k]))
                )
            ]
            ranked = sorted(kept, key=sizes.__getitem__)
            picks += [(s, units, found[units]) for units in ranked[: 2 * n + 2]]
        if not picks:
            return
        x = self.xs[[p[0] for p in picks]].astype(np.float64)
        for r, (s, units, values) in enumerate(picks):
            for u, v in zip(units, values):
                self._set(x, r, s, u, v)
        x = x.astype(self.policy.dtype)
        who = np.array([p[0] for p in picks])
        gap, scores = self._gap(x, who)
        np.add.at(self.evals, who, 1)
        after = self.units.values(x)
        avail = self.policy.available(x) if self.policy.output == "actions" else None
        for r, (s, units, _) in enumerate(picks):
            inside = all(self.low[s, u] <= after[r, u] <= self.high[s, u] for u in units)
            # a binary unit at one of its two values (a declared bound between them would leave a fraction)
            inside &= all(after[r, u] in self.units.levels[u] for u in units if self.units.binary[u])
            if gap[r] > 0 and inside and len(self.checked[s]) < n:
                cf = self._counterfactual(s, units, x[r], after[r], scores[r], gap[r], avail, r)
                # past the line by more than float32's noise at these scores' size (a re-run alone decides the same)
                size = np.abs(scores[r] if avail is None else scores[r][avail[r]]).max()
                if cf.margin > NOISE * max(1.0, float(size)):
                    self.checked[s].append(cf)

    def _set(self, x: np.ndarray, r: int, s: int, u: int, value: float) -> None:
        """Move unit ``u`` of row ``r`` (a copy of state ``s``) to ``value``, within its range once in the network's
        dtype (a single column is set, not shifted, so that rounding cannot carry it past its bound)."""
        cols = self.units.columns[u]
        if len(cols) > 1:
            self.units.move(x, r, u, value - self.own[s, u])
            return
        v = self.policy.dtype(value)
        lo, hi = self.low[s, u], self.high[s, u]
        if v > hi:
            v = np.nextafter(self.policy.dtype(hi), self.policy.dtype(-np.inf))
        if v < lo:
            v = np.nextafter(self.policy.dtype(lo), self.policy.dtype(np.inf))
        x[r, cols[0]] = v

    def _sizes(self, s: int, units, values) -> tuple[float, float]:
        """(quantile distance, scaled distance) of moving units ``units`` of state ``s`` to ``values``."""
        u, v = np.array(units), np.array(values)
        own = self.own[s, u]
        q = np.abs(self.units.quantile(v, u) - self.units.quantile(own, u)).sum()
        return float(q), float((np.abs(v - own) / self.scale[u]).sum())

    def _counterfactual(self, s, units, state, after, scores, gap, avail, r) -> Counterfactual:
        names, labels, policy = self.units.names, self.units.labels, self.policy
        units = sorted(units, key=lambda u: -self.push[s, u])
        q0 = self.units.quantile(self.own[s, list(units)], np.array(units))
        q1 = self.units.quantile(after[list(units)], np.array(units))
        changes = tuple(
            Change(names[u], float(self.own[s, u]), float(after[u]), labels[u], (float(a), float(b)))
            for u, a, b in zip(units, q0, q1)
        )
        dist, scaled = self._sizes(s, units, after[list(units)])
        if policy.output == "actions":
            a = int(np.argmax(np.where(avail[r], scores, -np.inf)))
            margin = lead(scores, avail[r], a)  # over the best other allowed action (a flip leaves at least two)
            action, output = policy.action_names[a], float(scores[a])
        else:
            j = self.goal.j
            action, output, margin = policy.action_names[j], float(scores[j]), float(gap)
        state = np.array(state, copy=True)
        state.setflags(write=False)
        return Counterfactual(changes, state, action, output, margin, dist, scaled)

    def result(self, s: int, index: int, max_changes: int) -> Counterfactuals:
        goal, names = self.goal, self.policy.action_names
        found = tuple(sorted(self.checked[s], key=lambda c: (c.distance, c.distance_scaled)))
        reason = ""
        if not found:
            reason = goal.skip[s] or (
                "no feature may change: every one is immutable, an identifier or a category"
                if not self.units.n
                else f"the search found no change of at most {max_changes} feature{'s' if max_changes > 1 else ''} "
                f"within the bounds that makes {goal.verb[s]} (a grid search: a miss is no proof that none exists)"
            )
        return Counterfactuals(index, names[goal.chosen[s]], goal.words[s], found, reason, int(self.evals[s]))


def _rows(index, n: int) -> np.ndarray:
    if index is None:
        return np.arange(n)
    if isinstance(index, bool) or not isinstance(index, (int, np.integer)):
        raise InputError(f"index is a state's row (a whole number) or None for all; got {index!r:.40}.")
    if not -n <= index < n:
        raise InputError(f"index {index} is out of range: there are {n} state(s).")
    return np.array([int(index) % n])
