"""SEARCH's height moves: first back to the height the target was last seen from (a climb may have hidden it), then
the sweep's legs, each turning at another height. Senses only (+1 up, -1 down, 0 none); the controller makes the
frames. ``Look``: the sweep's pause at a glimpse of something the target might be."""

from __future__ import annotations

from ..vision.detection import Detection

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


GLIMPSE_SHARE = 0.5  # a measured sighting at this share of the acquire confidence stops the sweep for a look
LOOK_MS = 1500  # the look: the sweep held this long (the turn's blur gone, a sighting may be confirmed)
LOOK_AGAIN_MS = 2500  # ... and after it the sweep turns on at least this long before another look


def glimpse(det: Detection | None, acquire_confidence: float) -> bool:
    """Whether ``det`` is a glimpse: measured (not bridged), at ``GLIMPSE_SHARE`` of the acquire confidence."""
    return det is not None and det.found and not det.predicted and det.confidence >= GLIMPSE_SHARE * acquire_confidence


class Look:
    """The sweep's pause at a glimpse: a sighting measured but under the acquire confidence. Turning at a control
    step, the target crosses the frame in about a second blurred by the turn (the exposure is 1/120-1/30 s), and
    its confidence stays under the acquire level all the way (``ahead`` 3015, 3016: 0.2-0.47): the sweep went past
    it. The look holds the heading for ``LOOK_MS``; after it the sweep turns on ``LOOK_AGAIN_MS`` before another,
    so a distractor or a target that stays unconfirmed delays it by a bounded share."""

    def __init__(self) -> None:
        self._until_ms: int | None = None
        self._quiet_until_ms = 0

    def holds(self, now_ms: int, glimpse: bool) -> bool:
        """Whether the sweep holds for a look in this frame (``glimpse``: this frame's sighting is one)."""
        if self._until_ms is not None and now_ms < self._until_ms:
            return True
        self._until_ms = None
        if glimpse and now_ms >= self._quiet_until_ms:
            self._until_ms = now_ms + LOOK_MS
            self._quiet_until_ms = self._until_ms + LOOK_AGAIN_MS
            return True
        return False
