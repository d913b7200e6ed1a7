"""What a counterfactual search answers (issue 56): for one decision, the smallest changes of at most a few features
that make the policy choose another action, each one run through the policy before it is returned.

These types are the contract between the search (:mod:`xairl.counterfactuals.search`), the narration unit that says
one in words (its numbers tracked facts like every other), the check that re-runs the policy on a stated change, and
the places that show them (CLI, report, notebook, review page).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from xairl.errors import InputError


@dataclass(frozen=True)
class Threshold:
    """The target of a continuous action or a value: the decision 'changes' when output ``output`` (an index or a
    name) crosses ``above`` (rises above it) or ``below`` (falls below it); exactly one of them is given."""

    output: int | str = 0
    above: float | None = None
    below: float | None = None

    def __post_init__(self) -> None:
        if (self.above is None) == (self.below is None):
            raise InputError(
                "a Threshold takes exactly one of above=... or below=..., e.g. Threshold('steer', above=0)."
            )
        bound = self.above if self.above is not None else self.below
        if isinstance(bound, bool) or not isinstance(bound, (int, float, np.number)) or not np.isfinite(bound):
            raise InputError(f"a Threshold's bound is a finite number; got {bound!r:.40}.")


@dataclass(frozen=True)
class Change:
    """One feature's change: ``before`` in the state, ``after`` in the counterfactual, both in the feature's own
    ``unit`` (a region of an image: its mean pixel value; every pixel of it shifted by the same amount). ``quantiles``
    is (before, after) as positions 0..1 in the background's distribution of the feature (NaN when unknown)."""

    feature: str
    before: float
    after: float
    unit: str = ""
    quantiles: tuple[float, float] = (float("nan"), float("nan"))

    @property
    def delta(self) -> float:
        return self.after - self.before

    def __repr__(self) -> str:
        return f"{self.feature} {self.before:.4g} -> {self.after:.4g}{' ' + self.unit if self.unit else ''}"


@dataclass(frozen=True)
class Counterfactual:
    """One changed state that flips the decision, checked by running the policy on it.

    :param changes: the features changed (at most ``max_changes``), largest push first.
    :param state: the changed state, flat (n_features,), exactly what was run through the policy.
    :param action: the action the policy takes in ``state`` (for a :class:`Threshold`: the output's name).
    :param output: the policy's score of ``action`` in ``state`` (a threshold target: the output's value).
    :param margin: how far past the line the changed state is: the score of ``action`` minus the best other available
        action's (> 0), or the output's distance past the threshold (>= 0).
    :param distance: sum over the changes of |quantile after - quantile before| (background quantiles; 0..max_changes);
        ``distance_scaled`` the sum of |after - before| / the feature's interquartile range (own units, scaled).
    """

    changes: tuple[Change, ...]
    state: np.ndarray
    action: str
    output: float
    margin: float
    distance: float
    distance_scaled: float

    def __repr__(self) -> str:
        """One line (the changed state is left out)."""
        changes = " and ".join(repr(c) for c in self.changes)
        return f"Counterfactual({changes}: {self.action}, margin {self.margin:.3g}, distance {self.distance:.3g})"


@dataclass(frozen=True)
class Counterfactuals:
    """The answer for one decision: the counterfactuals found, best (smallest ``distance``) first, or none.

    :param index: the state's row in the states searched.
    :param chosen: the action the policy took (for a :class:`Threshold`: the output's name).
    :param target: what was asked, in words: the runner-up's name, a named action, 'any other action', or
        'steer above 0.5'.
    :param found: empty when the search found no change of at most ``max_changes`` features within the bounds that flips
        the decision (a grid search: a miss is no proof that none exists).
    :param reason: why none was found, in one line ('' when some were).
    :param evaluations: states run through the policy by the search.
    """

    index: int
    chosen: str
    target: str
    found: tuple[Counterfactual, ...]
    reason: str = ""
    evaluations: int = 0

    @property
    def reachable(self) -> bool:
        return bool(self.found)

    @property
    def best(self) -> Counterfactual | None:
        return self.found[0] if self.found else None

    def __repr__(self) -> str:
        """One line: the decision, then the best counterfactual (and how many more), or why there is none."""
        head = f"Counterfactuals(state {self.index}: chose {self.chosen}, asked {self.target}"
        if not self.found:
            return f"{head}; none found: {self.reason})"
        more = f"; {len(self.found) - 1} more" if len(self.found) > 1 else ""
        return f"{head}; best {self.found[0]!r}{more})"

    def _repr_html_(self) -> str:
        """Jupyter's view: the card of the report's decisions ('What would have changed it')."""
        from xairl.counterfactuals.show import summary
        from xairl.explanations.display import CF_STYLE, counterfactual_html

        return f"<style>{CF_STYLE}</style>" + counterfactual_html(summary(self))
