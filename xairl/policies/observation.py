"""What a policy's states look like (one flat vector, an image, a dict of arrays, several inputs) and the one flat
(n, F) feature matrix every attributor works on.

Data flows one way: user states -> :meth:`Observation.flatten` -> (n, F) float32 -> attributors, which call the
policy's network through :meth:`Observation.unflatten` (a view and a split, both linear, so every attribution
method sees through them).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from itertools import product
from typing import Any

import numpy as np

from xairl.errors import InputError
from xairl.policies.region_names import region_extent, region_name, region_size
from xairl.policies.windows import Window

KINDS = ("flat", "array", "dict", "tuple", "window")
#: what an image's channels are: 'channels' (colours, feature maps) or 'frames' (a frame stack)
CHANNELS = ("channels", "frames")


@dataclass(frozen=True)
class Part:
    """One input of the module.

    :param key: the dict key (or 'input{i}' for a tuple part, 'obs' for a single array).
    :param shape: the shape of one state of this part, e.g. (4, 84, 84); ``()`` for a scalar.
    :param categories: for a discrete input given as integers: how many values it takes (it is explained as that
        many one-hot columns ``key=v``); ``None`` for numbers used as they are.
    :param channels: what the first axis of an image (C, H, W) holds: 'channels' (colours, feature maps), or
        'frames' for a frame stack (4 stacked Atari frames), whose regions are then said as 'patch F6 of frame 2'.
    :param window: for a window of observations (:mod:`xairl.policies.windows`): its signals, steps and layout; ``shape``
        is then (steps, signals).
    """

    key: str
    shape: tuple[int, ...]
    categories: int | None = None
    channels: str = "channels"
    window: Window | None = None

    def __post_init__(self) -> None:
        if self.channels not in CHANNELS:
            raise InputError(
                f"channels='{self.channels}' of '{self.key}' is unknown; use one of {', '.join(CHANNELS)}."
            )

    @property
    def size(self) -> int:
        """Columns this part takes in the flat feature matrix."""
        return self.categories if self.categories else int(np.prod(self.shape, dtype=np.int64))

    def names(self, single: bool) -> list[str]:
        if self.window is not None:
            return self.window.names()
        if self.categories:
            return [f"{self.key}={v}" for v in range(self.categories)]
        if not self.shape:
            return [self.key]
        if single and len(self.shape) == 1:
            return [f"{self.key}_{i}" for i in range(self.shape[0])]
        return [f"{self.key}[{','.join(map(str, ix))}]" for ix in product(*(range(s) for s in self.shape))]


@dataclass(frozen=True)
class Observation:
    """The structure of a policy's input.

    :param kind: 'flat' (one vector per state), 'array' (one array per state, e.g. an image (C, H, W)), 'dict'
        (a dict of arrays: Dict observations) or 'tuple' (the module takes several tensors).
    :param parts: the inputs in flat-column order.
    """

    kind: str
    parts: tuple[Part, ...]

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise InputError(f"observation kind '{self.kind}' is unknown; use one of {', '.join(KINDS)}.")

    # ---- constructors -------------------------------------------------------------------------------------
    @classmethod
    def flat(cls, n_features: int) -> Observation:
        return cls("flat", (Part("obs", (int(n_features),)),))

    @classmethod
    def array(cls, shape: Sequence[int], key: str = "obs", channels: str = "channels") -> Observation:
        """States of shape ``(n, *shape)``, e.g. frames (n, 4, 84, 84); ``channels="frames"`` says that the first axis
        of an image is a frame stack (its regions are said as 'patch F6 of frame 2', not 'of channel 2')."""
        shape = tuple(int(s) for s in shape)
        if len(shape) < 2:  # a vector is 'flat': the explanation records either, and reads back the one it is
            raise InputError(
                f"Observation.array takes 2 axes or more, got {shape}; one vector per state is Observation.flat(n)."
            )
        return cls("array", (Part(key, shape, channels=channels),))

    @classmethod
    def dict(
        cls,
        shapes: Mapping[str, Sequence[int] | int],
        categories: Mapping[str, int] | None = None,
        channels: Mapping[str, str] | None = None,
    ) -> Observation:
        """A dict of arrays; ``categories`` names the keys holding integer categories (one-hot encoded), ``channels``
        the image keys whose channels are 'frames' of a stack (:class:`Part`)."""
        categories, channels = dict(categories or {}), dict(channels or {})
        parts = []
        for key, shape in shapes.items():
            shape = (shape,) if isinstance(shape, int) else tuple(int(s) for s in shape)
            parts.append(Part(str(key), shape, categories.get(key), channels.get(key, "channels")))
        return cls("dict", tuple(parts))

    @classmethod
    def window(
        cls, signals: Sequence[str], steps: int, layout: str = "sequence", step_s: float | None = None
    ) -> Observation:
        """The last ``steps`` observations of ``signals`` (:class:`xairl.policies.windows.Window`): states (n, steps,
        signals) or flat (n, steps * signals), time-major, oldest first; the module takes (n, steps, signals)
        (``layout='sequence'``: a GRU/LSTM with batch_first, an MLP that flattens) or the flat rows ('stacked')."""
        w = Window(tuple(signals), steps, layout, step_s)
        return cls("window", (Part("obs", w.shape, window=w),))

    @classmethod
    def several(cls, shapes: Sequence[Sequence[int]]) -> Observation:
        """Several inputs, passed to the module as positional tensors ``module(x0, x1, ...)``."""
        shapes = list(shapes)
        if len(shapes) < 2:
            raise InputError(
                f"several inputs take 2 shapes or more, got {len(shapes)}; one input is given by its shape, e.g. "
                "observation=(4, 84, 84)."
            )
        return cls("tuple", tuple(Part(f"input{i}", tuple(int(s) for s in sh)) for i, sh in enumerate(shapes)))

    # ---- the flat view --------------------------------------------------------------------------------------
    @property
    def n_features(self) -> int:
        return sum(p.size for p in self.parts)

    def feature_names(self) -> list[str]:
        single = len(self.parts) == 1
        if self.kind == "flat":
            return [f"obs_{i}" for i in range(self.n_features)]
        return [n for p in self.parts for n in p.names(single and self.kind == "array")]

    def slices(self) -> dict[str, slice]:
        """Columns of each part in the flat matrix."""
        out, start = {}, 0
        for p in self.parts:
            out[p.key] = slice(start, start + p.size)
            start += p.size
        return out

    def describe(self) -> str:
        """The states' form in messages: ``(n, 4, 84, 84)``, ``{image: (n, 3, 8, 8), v: (n, 5)}``, ``((n, 4), (n, 2))``."""
        shapes = [f"(n, {', '.join(map(str, p.shape))})" for p in self.parts]
        if self.kind in ("flat", "array", "window"):
            return shapes[0]
        if self.kind == "dict":
            return "{" + ", ".join(f"{p.key}: {s}" for p, s in zip(self.parts, shapes)) + "}"
        return "(" + ", ".join(shapes) + ")"

    def flatten(self, states: Any, what: str = "states", dtype=np.float32) -> np.ndarray:
        """States in any form this observation accepts -> a checked matrix (n, n_features) of ``dtype`` (the
        network's: float32, or float64 for a float64 network), finite after the cast.

        Accepted: the flat matrix itself (n, F) or one flat row (F,); for 'array' also (n, *shape) or one state
        (*shape); for 'dict' a mapping of key -> (n, *shape) (integers for categorical keys); for 'tuple' a
        sequence of arrays, one per input.
        """
        if self.kind == "dict" and len(self.parts) == 1 and not isinstance(states, Mapping):
            states = {self.parts[0].key: states}  # one categorical input (a Discrete observation)
        if isinstance(states, Mapping):
            if self.kind != "dict":
                raise InputError(f"{what}: got a dict but this policy takes {self.describe()}; pass an array.")
            return _finite(np.concatenate(self._columns(states, what), axis=1), what, dtype)
        if (
            isinstance(states, (tuple, list))
            and self.kind == "tuple"
            and len(states) == len(self.parts)
            and all(hasattr(s, "shape") for s in states)
        ):
            return _finite(
                np.concatenate(self._columns(dict(zip([p.key for p in self.parts], states)), what), axis=1), what, dtype
            )
        arr = _numeric(states, what)
        f = self.n_features
        if self.kind in ("array", "window"):
            shape = self.parts[0].shape
            if arr.shape == shape:
                arr = arr[None]
            if arr.ndim == len(shape) + 1 and arr.shape[1:] == shape:
                arr = arr.reshape(len(arr), f)  # f, not -1: numpy cannot infer -1 for no states
        if arr.ndim == 1 and arr.size == f:
            arr = arr[None, :]
        if arr.ndim != 2:
            shape = f"a 2-D array (n, {f})" if self.kind == "flat" else f"{self.describe()} or a flat (n, {f}) array"
            raise InputError(f"{what} must be {shape}; got shape {arr.shape}.")
        if arr.shape[0] == 0:
            raise InputError(f"{what} {_verb(what, 'are')} empty: give at least one state.")
        if arr.shape[1] != f:
            raise InputError(
                f"{what} {_verb(what, 'have')} {arr.shape[1]} features but the policy expects {f}"
                f"{' as ' + self.describe() if self.kind != 'flat' else ''}; check the column order/count."
            )
        return _finite(arr, what, dtype)

    def _columns(self, states: Mapping, what: str) -> list[np.ndarray]:
        missing = [p.key for p in self.parts if p.key not in states]
        if missing:
            raise InputError(
                f"{what} {_verb(what, 'lack')} key(s) {', '.join(missing)}; the policy takes {self.describe()}."
            )
        cols, n = [], None
        for p in self.parts:
            a = _numeric(states[p.key], f"{what}['{p.key}']")
            if p.categories:
                a = a.reshape(len(a), -1 if len(a) else 1) if a.ndim > 1 else a[:, None]
                if a.shape[1] != 1 or not np.all((a == np.round(a)) & (a >= 0) & (a < p.categories)):
                    raise InputError(f"{what}['{p.key}'] must hold one integer in 0..{p.categories - 1} per state.")
                a = np.eye(p.categories, dtype=np.float64)[a[:, 0].astype(int)]
            else:
                if a.shape == p.shape:
                    a = a[None]
                if a.shape[1:] != p.shape:
                    raise InputError(
                        f"{what}['{p.key}'] has shape {a.shape}; expected (n, {', '.join(map(str, p.shape))})."
                    )
                a = a.reshape(len(a), p.size)
            if n is not None and len(a) != n:
                raise InputError(f"{what}: the parts have different numbers of states ({n} and {len(a)}).")
            n = len(a)
            cols.append(a)
        if n == 0:
            raise InputError(f"{what} is empty: give at least one state.")
        return cols

    def unflatten(self, x):
        """A torch (n, F) tensor -> what the module takes: one tensor, a dict of tensors, or a tuple of them."""
        if self.kind == "flat" or (self.kind == "window" and self.parts[0].window.layout == "stacked"):
            return x
        out = {
            p.key: x[:, s].reshape(len(x), *(p.shape if not p.categories else (p.categories,)))
            for p, s in zip(self.parts, self.slices().values())
        }
        if self.kind in ("array", "window"):
            return out[self.parts[0].key]
        return out if self.kind == "dict" else tuple(out.values())

    def image_shape(self) -> tuple[int, ...] | None:
        """(C, H, W) or (H, W) of an image observation; None for other kinds."""
        if self.kind == "array" and len(self.parts[0].shape) in (2, 3):
            return self.parts[0].shape
        return None

    def regions(self) -> dict[str, np.ndarray]:
        """Named patches of each channel of each image part (2-D or 3-D), for :meth:`Explanation.grouped`: what
        narration speaks of instead of pixels (:func:`xairl.policies.region_names.region_name`: 'patch F6 of frame 2');
        empty when no image part has patches larger than one pixel (a small image is narrated pixel by pixel)."""
        return {name: idx for name, _, idx in self._patches()}

    def time_groups(self) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]] | None:
        """(per signal, per step) column groups of an observation that holds time, for :meth:`Explanation.grouped`:
        a window's signals over their steps and its steps ('t-3' ... 't') over their signals; a frame stack's
        regions over its frames ('patch F6') and its frames ('frame 0' ... oldest first). None for other kinds."""
        p = self.parts[0]
        if self.kind == "window":
            return p.window.signal_columns(), p.window.step_columns()
        if self.kind != "array" or p.channels != "frames" or len(p.shape) != 3:
            return None
        c, h, w = p.shape
        size = region_size(h, w)
        idx = np.arange(c * h * w).reshape(c, h, w)
        regions = {
            region_name(r // size, q // size): idx[:, r : r + size, q : q + size].ravel()
            for r, q in product(range(0, h, size), range(0, w, size))
        }
        return regions, {f"frame {k}": idx[k].ravel() for k in range(c)}

    def region_extents(self) -> dict[str, str]:
        """Each region's name -> the pixels it covers in words, for tables, hover texts and details ('the 12x12 patch
        at rows 60 to 71, columns 60 to 71 of frame 2': :data:`xairl.policies.region_names.REGION_EXTENT`, counting from 0)."""
        return {name: extent for name, extent, _ in self._patches()}

    def _patches(self):
        """(name, extent, flat columns) of every region, in channel, row, column order."""
        single = len(self.parts) == 1
        for p, cols in zip(self.parts, self.slices().values()):
            if p.categories or p.window is not None or len(p.shape) not in (2, 3):
                continue
            c, h, w = (1, *p.shape) if len(p.shape) == 2 else p.shape
            size = region_size(h, w)
            if size == 1:
                continue
            idx = np.arange(cols.start, cols.stop).reshape(c, h, w)
            layer = p.channels[:-1]  # 'channel' or 'frame'
            for ch, r, q in product(range(c), range(0, h, size), range(0, w, size)):
                channel, key = (ch if c > 1 else None), (None if single else p.key)
                rows, columns = (r, min(r + size, h) - 1), (q, min(q + size, w) - 1)
                yield (
                    region_name(r // size, q // size, channel, key, layer),
                    region_extent(rows, columns, channel, key, layer),
                    idx[ch, r : r + size, q : q + size].ravel(),
                )

    def to_dict(self) -> dict:
        return {
            "kind": self.kind,
            "parts": [
                {"key": p.key, "shape": list(p.shape), "categories": p.categories}
                | ({"channels": p.channels} if p.channels != "channels" else {})
                | ({"window": p.window.to_dict()} if p.window is not None else {})
                for p in self.parts
            ],
        }

    @classmethod
    def from_dict(cls, d: Mapping) -> Observation:
        return cls(
            d["kind"],
            tuple(
                Part(
                    p["key"],
                    tuple(p["shape"]),
                    p.get("categories"),
                    p.get("channels", "channels"),
                    Window.from_dict(p["window"]) if p.get("window") else None,
                )
                for p in d["parts"]
            ),
        )


def names_preview(names: Sequence[str], what: str, shown: int = 3) -> str:
    """'12288 features: obs[0,0,0], obs[0,0,1], obs[0,0,2], ...': a count and the first ``shown`` names (all of them
    when there are at most ``shown + 2``), for reprs of policies and explanations."""
    names = list(names)
    head = names if len(names) <= shown + 2 else [*names[:shown], "..."]
    return f"{len(names)} {what}: {', '.join(head)}"


def _numeric(data, what: str) -> np.ndarray:
    if hasattr(data, "detach"):  # a torch tensor, without importing torch here
        data = data.detach().cpu().numpy()
    try:
        arr = np.asarray(data)
        if arr.dtype.kind in _REFUSED_KINDS:  # numpy would drop the imaginary part or count nanoseconds
            raise InputError(
                f"{what} {_verb(what, 'hold')} {_REFUSED_KINDS[arr.dtype.kind]} ({arr.dtype}); give real numbers "
                "(float or int), converting the column yourself if that is meant."
            )
        return arr.astype(np.float64)
    except (TypeError, ValueError, OverflowError) as exc:
        if isinstance(exc, InputError):
            raise
        raise InputError(f"{what} must be numeric; could not convert ({' '.join(str(exc).split())[:120]}).") from None
    except RecursionError:
        raise InputError(f"{what} {_verb(what, 'are')} nested too deeply to be states.") from None


_REFUSED_KINDS = {"c": "complex numbers", "M": "dates", "m": "time spans"}


def _verb(what: str, plural: str) -> str:
    """The verb agreeing with ``what``: 'states contain', 'background contains', 'FILE: rows 0..99 contain' (the
    last word after the last ': ' says: a file's name or a row range is no noun)."""
    words = [w.lstrip("-") for w in what.rsplit(": ", 1)[-1].split() if w.lstrip("-").isalpha()]
    noun = (words or ["states"])[-1]
    return plural if noun.endswith("s") else {"are": "is", "have": "has"}.get(plural, plural + "s")


def _finite(arr: np.ndarray, what: str, dtype=np.float32) -> np.ndarray:
    bad = ~np.isfinite(arr)
    if bad.any():
        r, c = np.argwhere(bad)[0]
        raise InputError(
            f"{what} {_verb(what, 'contain')} {int(bad.sum())} NaN/inf value(s), first at row {r}, column {c}; clean or drop them."
        )
    with np.errstate(over="ignore"):  # reported below in one line, not as a numpy warning
        out = arr.astype(dtype)
    over = ~np.isfinite(out)  # finite numbers beyond float32's range (~3.4e38) become inf in the cast
    if over.any():
        r, c = np.argwhere(over)[0]
        raise InputError(
            f"{what} {_verb(what, 'hold')} {int(over.sum())} value(s) beyond the {np.dtype(dtype).name} range (±"
            f"{np.finfo(dtype).max:.2g}) the network computes in, first at row {r}, column {c} ({arr[r, c]:.3g}); "
            "scale those inputs down, or give a float64 network (module.double())."
        )
    return out
