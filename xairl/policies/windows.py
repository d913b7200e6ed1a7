"""Windows: a policy whose input is its last k observations (an MLP over a window, a GRU/LSTM over a sequence, a
frame stack of vectors) and explanations that speak per signal, per time step and of trends.

A window's flat columns are time-major, oldest step first: ``speed[t-3], angle[t-3], ..., speed[t], angle[t]``;
``t`` is the newest observation. By additivity, a signal's contribution is the sum over its slots and a step's the
sum over its signals (:meth:`Explanation.by_signal`, :meth:`Explanation.by_step`); nothing is approximated.

A signal is said as a **trend** when its earlier slots carry at least :data:`TREND_SHARE` of its push (the policy
weighs where the signal came from, not only where it is) and its value changed over the window: "the serving RSRQ
fell 4.1 dB over the last 0.8 s". The change, its word and the window are facts of the decision, tracked and
verified like the contribution (:class:`xairl.facts.FeatureFact`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from xairl.errors import InputError

#: how a window reaches the module: 'sequence' (n, steps, signals), as a GRU/LSTM with batch_first and an MLP that
#: flattens its input take it; 'stacked' (n, steps * signals), time-major, as a vector frame stack (SB3's
#: VecFrameStack) is
LAYOUTS = ("sequence", "stacked")
#: the share of a signal's |contribution| its earlier slots must carry for it to be said as a trend
TREND_SHARE = 1 / 3
#: the trend words, by the sign of the change (newest minus oldest value)
RISE, FALL = "rose", "fell"
#: what fills a window's steps before an episode has that many observations (SB3's VecFrameStack: zeros)
PADDING = 0.0
#: a signal's steps 'pulled both ways' when their pushes nearly cancel (their sum is at most this share of their
#: sizes) though their sizes add up to as much as the decision's largest push: the heat map shows it dark while its
#: sum ranks it low, and a reader is owed why
CANCEL_SHARE = 0.25
BOTH_WAYS = "pulled both ways"
#: the most slots (steps x signals) a window may have: every slot is a feature, named, attributed and kept per
#: state, so a window is as wide as an image (3 x 224 x 224 is 150,528 columns); past this its names alone take
#: hundreds of MB, and ``window=10**8`` would build names until memory ran out
MAX_SLOTS = 1_000_000
#: a name as a window's slots are named: 'speed[t-3]', 'speed[t]', or a frame stack's 'patch A1 of frame 2'
SLOT_FORM = re.compile(r"(.+)\[t(?:-\d+)?\]|(.+) of frame \d+", re.S)


@dataclass(frozen=True)
class Window:
    """The last ``steps`` observations of ``signals``, one row per step, oldest first.

    :param signals: the name of each signal (one column of one observation).
    :param steps: observations in the window (k).
    :param layout: one of :data:`LAYOUTS`.
    :param step_s: seconds between two observations, when they are evenly spaced in time: trends are then said
        'over the last 0.8 s' instead of 'over the last 5 observations'.
    :param frames: the regions of a frame stack over its frames (:func:`xairl.policies.regions.in_regions`): steps are named
        'frame 0' ... (oldest first), slots 'patch F6 of frame 2', and the span 'the last 4 frames'.
    """

    signals: tuple[str, ...]
    steps: int
    layout: str = "sequence"
    step_s: float | None = None
    frames: bool = False

    def __post_init__(self) -> None:
        if isinstance(self.signals, str) or not isinstance(self.signals, (list, tuple)):
            raise InputError(
                f"a window's signals are a list of names, one per column of one observation; got {self.signals!r:.60}."
            )
        object.__setattr__(self, "signals", tuple(str(s) for s in self.signals))
        steps = self.steps
        if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 2:
            raise InputError(
                f"a window's steps are a whole number of observations, at least 2; got {steps!r:.40} (a single "
                "observation is a plain policy: leave window out)."
            )
        object.__setattr__(self, "steps", int(steps))
        if self.layout not in LAYOUTS:
            raise InputError(f"window layout '{self.layout}' is unknown; use one of {', '.join(LAYOUTS)}.")
        if not self.signals:
            raise InputError("a window needs at least one signal: name each column of one observation.")
        if len(set(self.signals)) != len(self.signals):
            raise InputError(f"the window's signals have duplicates ({', '.join(self.signals)}); name each once.")
        if len(self.signals) * self.steps > MAX_SLOTS:
            raise InputError(
                f"a window of {self.steps} steps x {len(self.signals)} signal(s) has {self.steps * len(self.signals):,} "
                f"slots, more than the {MAX_SLOTS:,} xairl explains (each slot is a feature); give the steps the "
                "module really takes."
            )
        slotted = [s for s in self.signals if SLOT_FORM.fullmatch(s)]
        if slotted:
            raise InputError(
                f"the window's signal '{slotted[0]:.60}' is named like a slot ('signal[t-1]', 'x of frame 2'), so "
                "its slots could be read as another signal's; rename it."
            )
        step = self.step_s
        if step is not None and (
            isinstance(step, bool) or not isinstance(step, (int, float, np.number)) or not 0 < step < float("inf")
        ):
            raise InputError(f"the window's step_s is the seconds between two observations (> 0); got {step!r:.40}.")

    @property
    def shape(self) -> tuple[int, int]:
        return self.steps, len(self.signals)

    def step_names(self) -> list[str]:
        """``t-3, t-2, t-1, t`` for 4 steps (a frame stack's ``frame 0`` ... ``frame 3``): the oldest first."""
        if self.frames:
            return [f"frame {k}" for k in range(self.steps)]
        return [f"t-{d}" if d else "t" for d in range(self.steps - 1, -1, -1)]

    def names(self) -> list[str]:
        """Every slot's feature name, time-major: ``signal[t-3]`` ... ``signal[t]`` (a frame stack's ``patch A1 of
        frame 0`` ...)."""
        slot = "{s} of {step}" if self.frames else "{s}[{step}]"
        return [slot.format(s=s, step=step) for step in self.step_names() for s in self.signals]

    def signal_columns(self, offset: int = 0) -> dict[str, np.ndarray]:
        """Each signal's columns, oldest step first (for :meth:`Explanation.grouped`)."""
        n = len(self.signals)
        return {s: offset + j + n * np.arange(self.steps) for j, s in enumerate(self.signals)}

    def step_columns(self, offset: int = 0) -> dict[str, np.ndarray]:
        """Each step's columns, every signal (for :meth:`Explanation.grouped`)."""
        n = len(self.signals)
        return {step: offset + n * k + np.arange(n) for k, step in enumerate(self.step_names())}

    def span_text(self, steps: int | None = None) -> str:
        """The span of the newest ``steps`` (default: all) in words: 'the last 0.8 s' from the oldest to the newest
        observation (with ``step_s``), else 'the last 5 observations'."""
        steps = self.steps if steps is None else steps
        if self.step_s is not None:
            seconds = (steps - 1) * self.step_s
            return f"the last {seconds / 60:.3g} min" if seconds >= 120 else f"the last {seconds:.3g} s"
        return f"the last {steps} {'frames' if self.frames else 'observations'}"

    def to_dict(self) -> dict:
        out = {"signals": list(self.signals), "steps": self.steps, "layout": self.layout, "step_s": self.step_s}
        return out | ({"frames": True} if self.frames else {})

    @classmethod
    def from_dict(cls, d) -> Window:
        return cls(
            tuple(d["signals"]), int(d["steps"]), d.get("layout", "sequence"), d.get("step_s"), bool(d.get("frames"))
        )


@dataclass(frozen=True)
class Trend:
    """How one signal moved over the window, and whether its push is said as a trend.

    :param change: the newest value minus the oldest (NaN when states are unknown).
    :param word: :data:`RISE` or :data:`FALL` when the signal is said as a trend, else ''.
    :param history: the share of its |contribution| its earlier slots carry (0..1).
    """

    change: float
    word: str
    history: float


def trend(values: np.ndarray, contributions: np.ndarray) -> Trend:
    """The trend of one signal: ``values`` and ``contributions`` are its slots, oldest first."""
    values, contributions = np.asarray(values, float), np.asarray(contributions, float)
    change = float(values[-1] - values[0]) if values.size else float("nan")
    size = np.abs(contributions)
    history = float(size[:-1].sum() / size.sum()) if size.sum() > 0 else 0.0
    said = history >= TREND_SHARE and np.isfinite(change) and change != 0
    return Trend(change, (RISE if change > 0 else FALL) if said else "", history)


def pulled_both_ways(contributions: np.ndarray, largest: float) -> str:
    """:data:`BOTH_WAYS` when a signal's slots (``contributions``) cancel out within :data:`CANCEL_SHARE` of their
    sizes, which add up to at least ``largest`` (the largest |contribution| of a reason); else ''."""
    contributions = np.asarray(contributions, float)
    size = float(np.abs(contributions).sum())
    return BOTH_WAYS if 0 < largest <= size and abs(contributions.sum()) <= CANCEL_SHARE * size else ""


def signal_facts(unit, states, contrib, start: int, largest: float) -> tuple:
    """(change, trend word, span, change's unit, :func:`pulled_both_ways`) of a narration unit
    (:class:`xairl.facts.Unit`) over one state's ``states`` and ``contrib`` (one per column): for a signal of a
    window, observed from step ``start`` on (a change from the padding before it is no trend; a label or an
    identifier has none), ``largest`` the decision's largest push; nothing for any other unit."""
    if unit.window is None:
        return None, "", "", "", ""
    cols, info = list(unit.columns), unit.info
    values, contributions = np.asarray(states)[cols], np.asarray(contrib)[cols]
    steps = pulled_both_ways(contributions, largest) if info.kind != "identifier" else ""
    if info.kind != "numeric":
        return None, "", "", "", steps
    moved = trend(values[start:], contributions[start:])
    change, change_unit = said_change(moved.change, info.unit, info.capacity)
    return change, moved.word, unit.window.span_text(len(values) - start), change_unit, steps


def real_start(states: np.ndarray, window: Window) -> np.ndarray:
    """Per state of flat window ``states`` (n, steps * signals), the first step that was observed. A frame stack
    fills the steps an episode has not reached yet with :data:`PADDING` (SB3's VecFrameStack after a reset): its
    oldest steps whose every signal is exactly that are no observations, and a change from them no trend (a window
    that is padding throughout is taken whole: nothing in it changed)."""
    steps = np.asarray(states).reshape(len(states), window.steps, len(window.signals))
    pad = np.all(steps == PADDING, axis=2)
    return np.where(pad.all(axis=1), 0, np.argmin(pad, axis=1))  # argmin: the first step that is not padding


def slot_features(features: dict, window: Window | None) -> dict:
    """A window's :class:`FeatureInfo`: each signal's, given once, for every slot of it too (a slot's own wins)."""
    if window is None:
        return features
    slots = window.signal_columns()
    names = window.names()
    for s in window.signals:
        if s in features:
            for j in slots[s]:
                features.setdefault(names[j], features[s])
    return features


def check_slot_names(window: Window, names, what: str = "feature_names") -> None:
    """Names given to a window's columns: one in a slot's form ('a[t-1]') must be that very slot's name at its column,
    so that no name says another step or signal than the column holds (names in no slot form are the caller's own)."""
    slots = window.names()
    for j, name in enumerate(names):
        if SLOT_FORM.fullmatch(str(name)) and (j >= len(slots) or slots[j] != name):
            held = f"holds {slots[j]}" if j < len(slots) else "is past the window's last slot"
            raise InputError(
                f"{what}: column {j} is named '{str(name):.60}' but, for a window of {window.steps} steps x "
                f"{', '.join(window.signals)[:80]}, it {held}; the names and the window disagree."
            )


def window_of(exp) -> Window | None:
    """The window of an explanation of a window policy that keeps its states (not a grouped one); else None."""
    obs = exp.observation
    if obs is None or obs["kind"] != "window" or exp.states is None or len(exp.feature_names) != len(exp.states[0]):
        return None
    return Window.from_dict(obs["parts"][0]["window"])


def said_change(change: float, unit: str, capacity: float | None = None) -> tuple[float, str]:
    """(size, unit) of a change as narratives say it: a quantity with a capacity in percentage points of it (a
    buffer '12.5 percentage points' fuller, as its level is said in % full), a level in dBm or dBW in dB (a
    difference of two levels is a ratio), any other in its own unit."""
    if capacity:
        return 100.0 * change / capacity, "percentage points"
    return change, {"dBm": "dB", "dBW": "dB"}.get(unit, unit)


def over_time(contributions: np.ndarray, signals: dict[str, np.ndarray], steps: dict[str, np.ndarray]) -> np.ndarray:
    """Cells (n, signals, steps) of ``contributions`` (n, F): each the sum of the columns of that signal at that
    step (:meth:`Explanation.time_groups` gives the groups); a row sums to the signal's contribution, a column to
    the step's. A heat map's cells."""
    f = np.asarray(contributions).shape[1]
    owner = np.zeros((2, f), dtype=int)
    for row, groups in enumerate((signals, steps)):
        for k, cols in enumerate(groups.values()):
            owner[row, cols] = k
    cells = np.zeros((len(contributions), len(signals), len(steps)))
    np.add.at(cells.transpose(1, 2, 0), (owner[0], owner[1]), np.asarray(contributions, float).T)
    return cells
