"""A texture of round things: a blob of the target's colour with several others of its size close around it in the
search (petal cups, a polka-dot print) is a piece of a pattern, not a ball: a ball stands alone at its size. Reads the
whole frame's round search blobs, so it holds for every look's candidates. Figures: bench/vision/HISTORY.md."""

from __future__ import annotations

from collections.abc import Sequence

from cv2.typing import MatLike

from .score import SIZE

PEERS = 4  # this many blobs of a similar size nearby make a texture...
PEERS_SMALL = 2  # ...or this many, round a blob under SIZE's one
SIZE_RATIO = 1.5  # a peer is at most this many times larger or smaller
REACH = 4.0  # diameters from the blob's centre to a peer's
OWN = 0.6  # diameters: a search blob whose centre is this close is the blob itself

SearchBlob = tuple[float, MatLike, tuple[int, int, int, int]]  # area, contour, box (x, y, width, height)


def textured(cx: float, cy: float, size: float, blobs: Sequence[SearchBlob], scale: int) -> bool:
    """Whether a blob ``size`` px across at (cx, cy) (full resolution) has ``PEERS`` of ``blobs`` of a similar size
    within ``REACH`` diameters (``PEERS_SMALL`` under ``SIZE``'s one); ``blobs`` are the search's round ones, ``scale``
    times smaller than the frame."""
    need = PEERS_SMALL if size < SIZE[1] else PEERS
    if len(blobs) < need:  # too few to hold the peers
        return False
    lo, hi = size / SIZE_RATIO, size * SIZE_RATIO
    near, own = (REACH * size) ** 2, (OWN * size) ** 2
    peers = 0
    for _, _, (x, y, bw, bh) in blobs:
        if not lo <= max(bw, bh) * scale <= hi:
            continue
        d2 = ((x + bw / 2.0) * scale - cx) ** 2 + ((y + bh / 2.0) * scale - cy) ** 2
        if own <= d2 <= near:
            peers += 1
            if peers >= need:
                return True
    return False
