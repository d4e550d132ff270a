"""Times for people: a duration in seconds also in the unit that reads best (min, h, d, yr).

A creep lifetime of 1.2e7 s says little to a rock mechanician; "140 d" says it at once.  Seconds stay the
unit of every file and column; these words stand beside them (summary.json ``lifetime_readable``, the
analysis tables, the command's result line).
"""
from __future__ import annotations

import math

#: Units from the largest, with their length in seconds (a Julian year, 365.25 d, as astronomy's).
UNITS = (("yr", 365.25 * 86400.0), ("d", 86400.0), ("h", 3600.0), ("min", 60.0), ("s", 1.0))
#: Significant digits of a readable duration.
DIGITS = 2


def readable_duration(seconds) -> str | None:
    """``seconds`` in the largest unit of :data:`UNITS` in which it is at least 1 (seconds below a minute), to
    :data:`DIGITS` significant digits: 11520 -> "3.2 h", 1.2e7 -> "140 d", 1.23e8 -> "3.9 yr", 0.05 -> "0.05 s".
    None for None, NaN, infinite or negative times (no duration to tell)."""
    try:
        seconds = float(seconds)
    except (TypeError, ValueError):
        return None
    if not math.isfinite(seconds) or seconds < 0:
        return None
    name, length = next(((n, s) for n, s in UNITS if seconds >= s), UNITS[-1])
    value = float(f"{seconds / length:.{DIGITS}g}")
    return f"{value:g} {name}"
