"""The lock's hysteresis: a target once acquired stays sighted at a lower confidence while it stays the same thing.

The gate acquires a sighting at ``controller.acquire_confidence`` (``pilot/vision/gating.py``). A tracked ball's
confidence dips under that for frames on end while nothing about it changes: big and low in the frame as the drone
brakes near it (``ahead`` 3016: 0.52-0.58 at 1.4 m, in full view), partly behind a panel (``occluded`` 3018:
0.3-0.6; ``high`` 3011: 0.46-0.61 for a second on end). Six such frames in a row were a loss, and the search then
turned away from it; an ACQUIRE that needed three frames in a row at the full confidence never had them. Kept: found,
at ``KEEP_SHARE`` of the acquire confidence at least, and steady against the frame before (``gating.steady``: size
and centre), after a frame acquired at the full confidence. The laser needs the gate's confirmation, as before.
"""

from __future__ import annotations

from ..vision.detection import Detection
from ..vision.gating import steady

KEEP_SHARE = 0.5


class Lock:
    def __init__(self) -> None:
        self._last: Detection | None = None  # the last frame sighted: what the next must be steady against

    def sighted(self, det: Detection | None, acquired: bool, locked: bool, acquire_confidence: float) -> bool:
        """Whether this frame sights the target: ``acquired`` by the gate, or, ``locked`` on it, kept (above)."""
        if det is None or not det.found:
            self._last = None
            return False
        kept = acquired or (locked and self._last is not None and det.confidence >= KEEP_SHARE * acquire_confidence
                            and steady(self._last, det))
        self._last = det if kept else None
        return kept
