"""SEARCH's height moves: first back to the height the target was last seen from (a climb may have hidden it), then
the sweep's legs, each turning at another height. Senses only (+1 up, -1 down, 0 none); the controller makes the
frames."""

from __future__ import annotations

RETURN_TOL_M = 0.05  # a search's return to the height the target was seen from ends this close to it
RETURN_MAX_MS = 3000  # ... or this long after the search began


def return_sense(return_m: float, settles_m: float, elapsed_ms: int) -> int:
    """The climb or descent back to ``return_m`` from ``settles_m`` (0: there, or given up)."""
    off = return_m - settles_m
    if abs(off) <= RETURN_TOL_M or elapsed_ms > RETURN_MAX_MS:
        return 0
    return 1 if off > 0.0 else -1


def sweep_sense(elapsed_ms: int, leg_ms: int, step_ms: int) -> int:
    """The height change due this far into the sweep (0: turn): after each leg one step down, then two up, two
    down..., so the legs sweep at the start height, one step below it, one above it..."""
    t, k = elapsed_ms, 0
    while t >= leg_ms:
        t -= leg_ms
        moving = step_ms if k == 0 else 2 * step_ms
        if t < moving:
            return -1 if k % 2 == 0 else 1
        t -= moving
        k += 1
    return 0
