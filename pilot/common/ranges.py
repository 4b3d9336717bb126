"""One rule for a figure that must lie in a range, wherever the pilot checks one (its config's options, the
simulated world's figures): a real number, finite, within low..high, both inclusive. NaN, infinities, booleans
and anything that is not a number fail it alike, so each checker only says what it checks and how it reports."""

from __future__ import annotations

import math
from numbers import Integral, Real


def within(value: object, low: float, high: float) -> bool:
    """Is ``value`` a finite real number (not a bool) from ``low`` to ``high``, both inclusive?"""
    if isinstance(value, bool) or not isinstance(value, Real):
        return False
    if isinstance(value, Integral):  # exact, however large: a float of 10**400 would overflow
        return low <= int(value) <= high
    number = float(value)
    return math.isfinite(number) and low <= number <= high
