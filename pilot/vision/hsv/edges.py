"""Balls inside or against a surface of their own colour (a red ball on a red-brown saucer, in front of a red
motorbike's tank), cut free by the image's edges (detector.py, step 4).

The mask cannot tell the ball from the surface, but the image can: the ball's rim is an edge (its shading, its
slightly other hue) almost all the way round. Edges found in any colour channel are walls in the mask; the
pieces they leave are candidates, and their isolation is how much of the rim just outside them is an edge or
off the mask (a piece of a red surface cut by its texture is walled in only in part).
"""

from __future__ import annotations

from typing import NamedTuple

import cv2
import numpy as np
from cv2.typing import MatLike

from .shape import CIRCLE_48, share_set

CANNY = (60, 150)  # hysteresis thresholds on each 8-bit channel (40-100 and 80-200 found the same balls,
# bench/vision tuning photos; lower ones fray a ball's shaded side)
MIN_SIZE = 24.0  # px across: under this, texture edges cut red surfaces into round bits (tuning photos: every
# false detection this step added was 13-22 px, nearly every ball it found over 35 px)
PIECES = 4  # the largest round pieces of one window measured
WALL_GROWTH = 2.0  # px: the walls (a 1 px edge grown by a cross) take a pixel off each side of a piece

_CROSS = cv2.getStructuringElement(cv2.MORPH_CROSS, (3, 3))  # an 8-connected edge grown to a 4-connected wall
_SQUARE = np.ones((3, 3), np.uint8)


class Cut(NamedTuple):
    """A window's mask cut by its edges: the pieces left (contour, area), largest first, and where a rim
    is real (an edge, or off the mask)."""

    pieces: list[tuple[MatLike, float]]
    separated: MatLike


def cut_by_edges(roi: MatLike, mask: MatLike, kernel: MatLike | None, min_area: float, min_fill: float) -> Cut:
    """``roi``: the window's (smoothed) BGR pixels; ``mask``: its cleaned colour mask. Pieces filling less
    than ``min_fill`` of their box's disc are left out."""
    edges = np.zeros(mask.shape[:2], np.uint8)
    for channel in cv2.split(roi):
        edges |= cv2.Canny(channel, *CANNY)
    cut = cv2.bitwise_and(mask, cv2.bitwise_not(cv2.dilate(edges, _CROSS)))
    if kernel is not None:
        cut = cv2.morphologyEx(cut, cv2.MORPH_OPEN, kernel)
    # the pieces as components (areas and boxes in one pass; a textured surface leaves hundreds), the outline
    # traced only for the few kept; a piece in a hole of another is a component of its own
    _, labels, stats, _ = cv2.connectedComponentsWithStats(cut, connectivity=8)
    area, bw, bh = stats[1:, cv2.CC_STAT_AREA], stats[1:, cv2.CC_STAT_WIDTH], stats[1:, cv2.CC_STAT_HEIGHT]
    round_enough = (area >= min_area) & (area >= min_fill * np.pi * (np.maximum(bw, bh) / 2.0) ** 2)
    pieces = []
    for i in sorted(np.flatnonzero(round_enough), key=lambda k: -int(area[k]))[:PIECES]:
        x, y, w, h = (int(v) for v in stats[i + 1, :4])
        own = np.asarray(labels[y : y + h, x : x + w] == i + 1, np.uint8)
        c = max(cv2.findContours(own, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE, offset=(x, y))[0], key=len)
        if len(c) >= 8 and (a := float(cv2.contourArea(c))) >= min_area:
            pieces.append((c, a))
    separated = cv2.bitwise_or(cv2.bitwise_not(mask), cv2.dilate(edges, _SQUARE))
    return Cut(pieces, separated)


def walled_in(separated: MatLike, contour: MatLike) -> float:
    """The share of the circle just outside the piece's enclosing circle that is an edge or off the mask."""
    (cx, cy), r = cv2.minEnclosingCircle(contour)
    return share_set(separated, cx, cy, CIRCLE_48, r + 1.5)
