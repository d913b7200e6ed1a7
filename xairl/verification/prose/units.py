"""Units a number is written in: a unit at the end of a feature's name ('dist_km'), and a number written in
another unit of the same quantity ('900 m' of a name in km)."""

from __future__ import annotations

import re

_UNIT_IN_NAME = re.compile(r"(?:^|_)(km|m|cm|mm|min|s|h|kg|g)$", re.IGNORECASE)  # (not 'ms': wind_speed_ms is m/s)
#: (the feature's unit, a unit written after its value) -> how many of the written unit make one of the feature's
_CONVERSIONS = {
    ("km", "m"): 1e3,
    ("m", "km"): 1e-3,
    ("m", "cm"): 1e2,
    ("m", "mm"): 1e3,
    ("cm", "mm"): 10,
    ("h", "min"): 60,
    ("min", "s"): 60,
    ("s", "ms"): 1e3,
    ("min", "h"): 1 / 60,
    ("s", "min"): 1 / 60,
    ("ms", "s"): 1e-3,
    ("kg", "g"): 1e3,
    ("g", "kg"): 1e-3,
}
_WRITTEN_UNIT = re.compile(
    r"\s*(km|kilometres?|kilometers?|m|metres?|meters?|cm|mm|min|minutes?|s|seconds?|ms|h|"
    r"hours?|kg|g|grams?)\b",
    re.IGNORECASE,
)
_UNIT_WORDS = {
    "kilometre": "km",
    "kilometer": "km",
    "metre": "m",
    "meter": "m",
    "minute": "min",
    "second": "s",
    "hour": "h",
    "gram": "g",
}


def unit_in_name(name: str) -> str:
    """The unit a feature's name ends in ('km' of 'next_drop_dist_km'), '' for none."""
    m = _UNIT_IN_NAME.search(name)
    return m.group(1).lower() if m else ""


def written_scale(after: str, unit: str) -> tuple[str, float]:
    """The unit right after a number when it is a multiple of the feature's: a decimal prefix ('2 Mbit' for 2e6 bit,
    '12 kB' for 12,000 B) or a unit of the same kind ('600 m' for 0.6 km, '90 s' for 1.5 min): the written unit (a
    prefix alone for a prefixed one) and how many of the feature's unit make one of it; ('', 1.0) without one."""
    prefix = re.match(rf"\s*([kMG])\s?{re.escape(unit)}\b", after) if unit else None
    if prefix:
        return prefix.group(1), {"k": 1e3, "M": 1e6, "G": 1e9}[prefix.group(1)]
    written = _WRITTEN_UNIT.match(after) if unit else None
    if written:
        word = written.group(1).lower()
        word = _UNIT_WORDS.get(word.rstrip("s") if len(word) > 3 else word, word)
        factor = _CONVERSIONS.get((unit.lower(), word))
        if factor:
            return f"{word} (not {unit})", 1 / factor
    return "", 1.0
