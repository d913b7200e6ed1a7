"""How numbers are written in words: one rule for every narrative, fact text and counterfactual sentence.

It sits below the facts and the templates (both write numbers with it; the facts never import the templates), and
the verifier reads back what it writes: plain decimals, never scientific notation.
"""

from __future__ import annotations

import decimal
import math

#: the most decimals written: a smaller magnitude is written 0 (a contribution of 0.0000003 is no reason to name)
MAX_DECIMALS = 6


def format_number(x: float, signed: bool = False) -> str:
    """How every number in a narrative is written (the ``num`` and ``signed`` filters, and the facts' own texts):
    0 decimals from 100, 1 from 10, else 2, and more below 0.1 where a number needs them to keep 2 significant digits
    ('0.071', '0.0086': never fewer digits than a smaller number beside it), in plain decimals (0.00064, never
    6.4e-04), at most :data:`MAX_DECIMALS` of them."""
    x = float(x)
    a = abs(x)
    if x.is_integer() and a < 1e6:  # ids, counts
        s = f"{x:.0f}"
    elif a >= 100:
        s = f"{x:.0f}"
    elif a >= 10:
        s = f"{x:.1f}"
    elif a >= 0.1 or a == 0:
        s = f"{x:.2f}"
    else:
        s = _two_digits(x)
    if s.startswith("-") and float(s) == 0:
        s = s[1:]
    return ("+" + s) if signed and not s.startswith("-") else s


def _two_digits(x: float) -> str:
    """``x`` (0 < |x| < 0.1) to 2 significant digits, counted once rounded (0.0999 is '0.10'), without trailing zeros;
    '0' below the last decimal written."""
    places = min(1 - math.floor(math.log10(abs(x))), MAX_DECIMALS)
    rounded = abs(round(x, places))
    if rounded == 0:
        return "0"
    if rounded >= 0.1:  # 0.0999: written as 0.1 and above are, '0.10'
        return f"{x:.2f}"
    text = f"{x:.{min(1 - math.floor(math.log10(rounded)), MAX_DECIMALS)}f}"
    return text.rstrip("0").rstrip(".")  # as written before: a margin of '0.05', not '0.050'


def written_step(x: float) -> float:
    """The place of the last digit :func:`format_number` writes of ``x`` (1 for '120', 0.1 for '37.6', 0.0001 for
    '0.0012'): a value rounded to it is written exactly."""
    return 10.0 ** decimal.Decimal(format_number(x)).as_tuple().exponent
