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
    0 decimals from 100, 1 from 10, else 2; below 0.01, 3 significant digits in plain decimals (0.000644, never
    6.44e-04), at most :data:`MAX_DECIMALS` of them."""
    x = float(x)
    a = abs(x)
    if x.is_integer() and a < 1e6:  # ids, counts
        s = f"{x:.0f}"
    elif a >= 100:
        s = f"{x:.0f}"
    elif a >= 10:
        s = f"{x:.1f}"
    elif a >= 0.01 or a == 0:
        s = f"{x:.2f}"
    else:
        places = min(2 - math.floor(math.log10(a)), MAX_DECIMALS)
        s = f"{x:.{places}f}".rstrip("0").rstrip(".")  # 3 significant digits, as written before: '0.005', not '0.00500'
    if s.startswith("-") and float(s) == 0:
        s = s[1:]
    return ("+" + s) if signed and not s.startswith("-") else s


def written_step(x: float) -> float:
    """The place of the last digit :func:`format_number` writes of ``x`` (1 for '120', 0.1 for '37.6', 1e-05 for
    '0.00123'): a value rounded to it is written exactly."""
    return 10.0 ** decimal.Decimal(format_number(x)).as_tuple().exponent
