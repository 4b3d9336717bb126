"""A texture of round things: a blob of the target's colour with several others of its size close around it in the
search (a dahlia's petal cups, a polka-dot print) is a piece of a pattern, not a ball. A ball stands alone at its
size; a pattern repeats. The circle look applies the same idea inside one window (circles.py); this one
reads the whole frame's search blobs, so it holds for every look's candidates. A dot at a sparse print's edge or
corner, with fewer than ``PEERS`` neighbours in reach, is not caught by it.

Chosen on the dev seeds of the tuning and validation photos (bench/vision's own seeds and the held-out photos were
not used): the validation photos' empty views with a detection 30 -> 17 of 600, distractor views 38 -> 28 of 600,
the same balls found on the tuning photos (3,400) and one more on the validation photos (800). The peers are the
search's round blobs (detector.py's ``SEARCH_FILL``: those it would refine as a ball); counted of any shape, a shiny
saucer's noisy pieces made a texture round a ball: 1.5 points fewer balls under noise.

A blob under ``SIZE``'s one (18 px) has too few pixels to show its shape, so it needs less to be a pattern:
``PEERS_SMALL`` blobs of its size nearby. The validation photos' dahlia, blurred or compressed, leaves two or three of
its cups apart in the mask at 15-20 px, each round enough to pass for a ball. On 18,000 dev-seed views (bench/vision's
tuning and validation photos, seeds 21, 25, 31, 81 and 83; not the report's): empty views with a detection 27 -> 20
of 6,000, distractor views 39 -> 35 of 3,000, of 7,298 balls of 16 px or more 2 fewer found (validation photos,
perspective and clean), the tuning photos' views the same to a view. Under 20 px rather than 18: 3 more false
detections gone, 1 ball more lost and 1 gained.
"""

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
