"""Values read back from JSON that someone else wrote: a number there is an int or a float,
never true or false (which Python's ``bool`` would pass as 1 and 0)."""

from __future__ import annotations

import math


def number_or_nan(value) -> float:
    """``value`` as a float if it is a number (not true or false), else NaN."""
    return float(value) if isinstance(value, int | float) and not isinstance(value, bool) else math.nan


def whole_or(value, default: int = 0) -> int:
    """``value`` if it is a whole number >= 0 (as a log read back holds it), else ``default``."""
    return value if isinstance(value, int) and not isinstance(value, bool) and value >= 0 else default
