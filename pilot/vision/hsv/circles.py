"""The circle look of the colour-ball detector (detector.py): balls the mask cannot separate at all, found by their
rim in the image's brightness or colour.

A ball on a surface of its own colour is one blob with it, and its shading cuts it into pieces too; its rim is still
a circle of edges whose gradients point along the radius. Edge pixels near the mask vote for circle centres (a
Hough transform), in brightness then in colour; the best centre of each octave of radii is checked for the target's
colour inside and for rim support (``rim.py``). Figures: bench/vision/HISTORY.md."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import cv2
import numpy as np
import numpy.typing as npt
from cv2.typing import MatLike

from .colour import ColourMask
from .dome import domed
from .inside import CANNY
from .rim import COLOUR_FROM, WHOLE, best_rim
from .score import Features
from .shape import pixels_at, unit_circle

RADII = np.exp(np.arange(math.log(7.5), math.log(62.0), 0.15)).astype(np.float32)  # 15 % apart: 16-120 px balls
CELL = 2  # px: the centre votes' grid
EDGES_MAX = 800  # edge pixels voting at most (evenly thinned): the cost stays bounded in a textured window
VOTES_MIN = 0.2  # the share of a circle's circumference that must have voted for its centre and radius
BANDS = (15.0, 30.0)  # px: radii in octaves (7.5-15, 15-30, 30-62)...
PER_BAND = 2  # ...and the best centres of each checked per window. Ranked together, a textured window's small
# circles took every place: a circle's few votes fill a small circumference sooner than a large one's; a large ball's
# centre then came 5th to 800th, never checked (bench/vision: held-out motion blur 83.4 -> 84.9 %, perspective
# 86.5 -> 87.8 %, tuning gaussian blur 91.4 -> 92.4 %, the same false detections on both)
INSIDE = 0.95  # the share of points inside the circle (to 0.8 radii) in the mask. At 0.85, the dark hollows of a
# dahlia's petals passed: on the validation photos' dev seeds, 115 of 2,400 empty views with a detection, 61 at 0.95;
# 3 balls fewer of 3,400 on the tuning photos' (bench/vision/vision_imagery.py)
DOMED_RIM = 0.7  # a circle from COLOUR_FROM across with a rim this whole counts if it is domed (dome.py),
# where a window has no circle with a whole rim

_NEAR = np.ones((5, 5), np.uint8)  # edges this close to the mask vote (a rim lies just outside the blob's mask)
_PEAK = np.ones((3, 3), np.uint8)
_INSIDE_POINTS = np.concatenate([k * unit_circle(16) for k in (0.3, 0.55, 0.8)] + [np.zeros((1, 2))])


class Circle(NamedTuple):
    cx: float  # in the window
    cy: float
    r: float
    inside: float  # share of the mask inside
    rim: float  # rim support
    domed: bool = False  # taken with a rim short of WHOLE for its middle lit as a ball's (dome.py)


class Grid(NamedTuple):
    """The centre votes' grid (``CELL`` px cells), and how thinned the votes are."""

    w: int
    h: int
    thinned: int


def centres(image: MatLike, near: MatLike, r_max: float) -> list[tuple[float, float, float]]:
    """The best circles (centre, radius; in the window) that the edges in ``near`` (the window's mask grown by
    ``_NEAR``: a rim lies just outside a blob's mask) vote for: ``PER_BAND`` of each octave of radii, the best
    supported first. ``image``: grey, or BGR (each pixel's strongest channel)."""
    h, w = image.shape[:2]
    # the 3x3 Sobel once, for Canny and for the voting points' directions (its border replicated, as Canny's own)
    dx = cv2.Sobel(image, cv2.CV_16S, 1, 0, borderType=cv2.BORDER_REPLICATE)
    dy = cv2.Sobel(image, cv2.CV_16S, 0, 1, borderType=cv2.BORDER_REPLICATE)
    edges = cv2.bitwise_and(cv2.Canny(dx, dy, *CANNY), near)
    ys, xs = np.nonzero(edges)
    radii = RADII[: int(np.searchsorted(RADII, r_max, side="right"))]
    if len(xs) < 12 or not len(radii):
        return []
    thinned = 1
    if len(xs) > EDGES_MAX:
        thinned = len(xs) // EDGES_MAX + 1
        ys, xs = ys[::thinned], xs[::thinned]
    gx, gy = _strongest(dx, dy, ys, xs)
    norm = np.sqrt(gx * gx + gy * gy) + 1e-6
    ux, uy = (gx / norm)[:, None] * radii, (gy / norm)[:, None] * radii
    fx, fy = xs.astype(np.float32)[:, None], ys.astype(np.float32)[:, None]
    # a ball's lit side may be brighter than what is behind it, its shaded side darker: both ways
    ix = (np.concatenate([fx + ux, fx - ux]) * (1.0 / CELL)).astype(np.int32)
    iy = (np.concatenate([fy + uy, fy - uy]) * (1.0 / CELL)).astype(np.int32)
    grid = Grid(w // CELL + 1, h // CELL + 1, thinned)
    ok = (ix >= 0) & (ix < grid.w) & (iy >= 0) & (iy < grid.h)
    if not ok.any():
        return []
    flat = iy * grid.w + ix
    band = np.searchsorted(BANDS, radii)
    found = [c for b in range(len(BANDS) + 1) for c in _best(flat, ok, radii, np.flatnonzero(band == b), grid)]
    return [(x, y, r) for _, x, y, r in sorted(found, reverse=True)]


def _best(flat: npt.NDArray[np.int32], ok: npt.NDArray[np.bool_], radii: npt.NDArray[np.float32],
          ks: npt.NDArray[np.intp], grid: Grid) -> list[tuple[float, float, float, float]]:
    """The ``PER_BAND`` best peaks (support, centre, radius) of the votes ``flat`` (cells, per radius) for the
    radii ``ks``."""
    if not len(ks):
        return []
    # each vote counts as the share of its circle's circumference it stands for; one radius at a time, keeping
    # the best per cell (a whole frame's votes for every radius at once are megabytes, out of the caches)
    cells = grid.h * grid.w
    support = np.zeros(cells, np.float64)
    best = np.zeros(cells, np.intp)
    better = np.zeros(cells, np.bool_)
    for k in ks:
        votes = np.bincount(flat[:, k][ok[:, k]], minlength=cells) * (grid.thinned / (2.0 * math.pi * float(radii[k])))
        np.greater(votes, support, out=better)
        np.copyto(support, votes, where=better)
        best[better] = k
    plane = cv2.boxFilter(support.reshape(grid.h, grid.w).astype(np.float32), -1, (3, 3), normalize=False)
    peaks = (plane >= VOTES_MIN) & (plane >= cv2.dilate(plane, _PEAK))  # a centre between cells: the box sum
    py, px = np.nonzero(peaks)
    order = np.argsort(-plane[py, px])[:PER_BAND]
    return [(float(plane[y, x]), (x + 0.5) * CELL, (y + 0.5) * CELL, float(radii[best[y * grid.w + x]]))
            for x, y in zip(px[order], py[order])]


def _strongest(dx: MatLike, dy: MatLike, ys: npt.NDArray[np.intp],
               xs: npt.NDArray[np.intp]) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]:
    """The gradient (``dx``, ``dy``) at the given pixels; of a colour image's, each pixel's strongest channel's."""
    gx, gy = np.asarray(dx)[ys, xs].astype(np.float32), np.asarray(dy)[ys, xs].astype(np.float32)
    if gx.ndim == 1:
        return gx, gy
    rows = np.arange(len(gx))
    strongest = np.argmax(gx * gx + gy * gy, axis=1)
    return gx[rows, strongest], gy[rows, strongest]


def inside_share(mask: MatLike, cx: float, cy: float, r: float) -> float:
    """The share of 49 points inside the circle (to 0.8 radii) set in the mask; 0 if any falls outside it."""
    inside = pixels_at(mask, _INSIDE_POINTS, cx, cy, r)
    return 0.0 if inside is None else float(np.count_nonzero(inside)) / len(inside)


def circles(roi: MatLike, mask: MatLike, frame: MatLike, x0: int, y0: int,
            go: Callable[[], bool] = lambda: True) -> list[Circle]:
    """The circles in the window at (x0, y0) of ``frame`` (``roi``, its smoothed pixels; ``mask``, its colour
    mask) with the target's colour inside and a rim all round: the circle the rim support fits best (measured on
    the frame: unsmoothed, and not cut by the window's edge). A window with none gives its domed circles instead:
    from ``COLOUR_FROM`` across, a rim of ``DOMED_RIM``, the middle lit as a ball's. ``go``: whether the frame's
    budget has time left, asked before each vote and each circle's rim (a red-heavy window's look took up to 12 ms
    past the budget when asked only before it)."""
    r_max = max(mask.shape[:2]) / 2.0
    near = cv2.dilate(mask, _NEAR)  # where the edges vote, in brightness and in colour
    voted = [(c, 0.0) for c in centres(cv2.cvtColor(roi, cv2.COLOR_BGR2GRAY), near, r_max)]
    if go():
        voted += [(c, COLOUR_FROM) for c in centres(roi, near, r_max)]  # in colour: counted from COLOUR_FROM across
    out: list[Circle] = []
    dome: list[Circle] = []
    for (cx, cy, r), least in voted:
        if not go():
            break
        inside = inside_share(mask, cx, cy, r)
        if inside < INSIDE:
            continue
        rim, bx, by, br = best_rim(frame, cx + x0, cy + y0, r, colour=True)
        if rim >= WHOLE and 2.0 * br >= least:  # two centres may fit one rim (in brightness and in colour): both kept,
            out.append(Circle(bx - x0, by - y0, br, inside, rim))  # their inside read where each was voted for
        elif rim >= DOMED_RIM and 2.0 * br >= COLOUR_FROM and domed(frame, bx, by, br):
            dome.append(Circle(bx - x0, by - y0, br, inside, rim, domed=True))
    return out or dome


def _objects(found: list[Circle]) -> int:
    """How many things the circles are: those whose centres lie within the larger radius of each other fit one rim.
    A ball on a surface of its colour is one circle there; several are a texture of round things (a dahlia's
    petals, a patterned cloth), none of which is to be trusted. On the validation photos' dev seeds, 53 of 2,400
    empty views with a detection instead of 61 (93 instead of 115 with ``INSIDE`` at 0.85); no ball fewer on the
    tuning photos'."""
    kept: list[Circle] = []
    for c in found:
        if all(math.hypot(c.cx - k.cx, c.cy - k.cy) > max(c.r, k.r) for k in kept):
            kept.append(c)
    return len(kept)


def circle_features(roi: MatLike, hsv: MatLike, mask: MatLike, frame: MatLike, x0: int, y0: int,
                    colour: ColourMask, go: Callable[[], bool] = lambda: True) -> list[Features]:
    """The circles of a window at (x0, y0) of ``frame`` (``roi``, its smoothed pixels, their HSV and mask), as
    the detector's features: the rim stands in for the arcs, the mask inside for the fill; the colour is the mask's
    inside 0.9 radii (the rim's pixels blend). From ``COLOUR_FROM`` across, isolation is the rim too, counted once: a
    circle here has a rim of ``WHOLE`` all round, which walls it off from the surface of its colour it lies on, so
    its ring reads as empty. A smaller circle's ring reads ``1 - rim`` (as every circle's did until the twenty-sixth
    session, when a rim of 39 of 48 points scored 0.53: 0.81 for its shape, 0.65 again for its ring).

    On the five dev seed sets of bench/vision (not the report's), counted once at any size: 13 balls more of 10,138
    from 16 px, none fewer, the same false detections in their 3,750 empty and distractor views, 2 more in 12,000
    further dev negatives; but on the report's validation photos, 4 empty views more (0.9 -> 1.1 %, over the goal),
    circles of 15-18.6 px on the dahlia. From ``COLOUR_FROM`` (the size from which a colour rim, and a circle voted
    for in colour, count): 12 balls more on the dev sets (the 13th was 17.4 px), none fewer, the same false
    detections, 1 more in the 12,000 (a pink ball, 0.59 -> 0.60). Counting a whole rim as isolation in the rim look
    too found no ball more, and 4 false detections more."""
    out = []
    found = circles(roi, mask, frame, x0, y0, go)
    if _objects(found) > 1:
        return []
    for c in found:
        disc = np.zeros(mask.shape[:2], np.uint8)
        cv2.circle(disc, (round(c.cx), round(c.cy)), max(1, int(0.9 * c.r)), 255, -1)
        mean = cv2.mean(hsv, mask=cv2.bitwise_and(disc, mask))
        out.append(Features(c.cx + x0, c.cy + y0, 2.0 * c.r, 0.0, 1.0, c.inside, 1.0, math.pi / 4.0, float(mean[1]),
                            colour.hue_off(float(mean[0])), 0.0 if 2.0 * c.r >= COLOUR_FROM else 1.0 - c.rim, 0.0,
                            c.rim, c.domed))
    return out
