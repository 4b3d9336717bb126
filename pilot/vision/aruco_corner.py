"""The ArUco detector's look for a marker with one corner covered (a hand, the edge of a shelf): OpenCV reads
only whole quadrilaterals, and a cut corner makes the black square a pentagon.

Each convex pentagon of the thresholded frame is tried as a square with one corner cut: the two sides beside
each of its edges, prolonged, meet at the missing corner. The quadrilateral is unwarped into the marker's cells and
read; the cells of the covered corner (``COVERED`` x ``COVERED`` of them) are ignored, every other cell (border and
code) must match the configured marker in one of its four rotations. With nine of its 36 cells unread, a
4x4 marker still has 12 code bits to match: a random pattern matches them one time in 4,096, and the border too.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import cv2
import numpy as np
import numpy.typing as npt
from cv2.typing import MatLike

FloatArray = npt.NDArray[np.float64]
PX_PER_CELL = 8  # the unwarped marker's cells are read from this many pixels square
COVERED = 3  # cells of the covered corner ignored, in each direction (12 % of the square covers 2.1)
MISMATCH_MAX = 0  # cells read otherwise allowed: with 1 (a blurred cell at the cut), 13 of the 4,096 codes of 12 bits
# matched, and empty views of the tuning sources read a marker (1 of 4,500 on a dev seed, 0 with none allowed, for 5
# covered markers fewer of 300: 82.3 -> 80.7 %)
THRESH_WINDOWS, THRESH_C = (7, 23), 7  # adaptive thresholds: a small window first (75 % of covered markers alone,
# against 48 % for the large one, on the tuning photos: a marker on a dark surface joins it through a dark cover in
# the large window's threshold), then OpenCV's detector's largest (82 % with both)
APPROX = 0.04  # polygon approximation, share of the perimeter
MAX_VERTICES = 8  # a square with a covered corner: its cover's outline adds 1 to 4 corners to the square's
SIDE_RATIO = 0.5  # the shortest side of a marker seen at most 60 degrees off its axis, to its longest


def reference_cells(dictionary: cv2.aruco.Dictionary, marker_id: int) -> list[npt.NDArray[np.bool_]]:
    """The marker's cells with their black border (True: white), in its four rotations."""
    n = dictionary.markerSize + 2
    cells = cv2.aruco.generateImageMarker(dictionary, marker_id, n) > 127
    return [np.rot90(cells, k).copy() for k in range(4)]


Point = tuple[float, float]


def _intersect(p0: Point, p1: Point, q0: Point, q1: Point) -> Point | None:
    """Where the line through p0 and p1 meets the line through q0 and q1 (None: parallel)."""
    d1x, d1y, d2x, d2y = p1[0] - p0[0], p1[1] - p0[1], q1[0] - q0[0], q1[1] - q0[1]
    den = d1x * d2y - d1y * d2x
    if abs(den) < 1e-9:
        return None
    t = ((q0[0] - p0[0]) * d2y - (q0[1] - p0[1]) * d2x) / den
    return p0[0] + t * d1x, p0[1] + t * d1y


def cut_corner_quads(poly: FloatArray) -> list[FloatArray]:
    """The squares an outline of 5 to ``MAX_VERTICES`` corners may be with one corner covered: for each run of four
    consecutive sides (the two middle ones whole, the outer two the covered corner's sides, up to where the cover
    starts), the quadrilateral of their lines, its first corner the covered one, when its sides are of a square's
    proportions and the covered corner lies within a side's length of the outline."""
    out = []
    pts: list[Point] = [(float(x), float(y)) for x, y in poly]
    k = len(pts)
    edges = [(pts[i], pts[(i + 1) % k]) for i in range(k)]
    for i in range(k):
        e1, e2, e3, e4 = (edges[(i + j) % k] for j in range(4))
        corners = [_intersect(*e4, *e1), _intersect(*e1, *e2), _intersect(*e2, *e3), _intersect(*e3, *e4)]
        quad = [c for c in corners if c is not None]
        if len(quad) < 4:
            continue
        sides = [math.dist(quad[j], quad[j - 1]) for j in range(4)]
        if min(sides) < SIDE_RATIO * max(sides) or min(math.dist(p, quad[0]) for p in pts) >= max(sides):
            continue
        q = np.array(quad, np.float64)
        if cv2.isContourConvex(q.astype(np.float32)):
            out.append(q)
    return out


def read_cells(grey: MatLike, quad: FloatArray, n: int) -> npt.NDArray[np.bool_]:
    """The quad unwarped into ``n`` x ``n`` cells, each white or black (Otsu's threshold on the unwarped marker)."""
    s = n * PX_PER_CELL
    dst = np.array([[0, 0], [s, 0], [s, s], [0, s]], np.float32)
    hm = cv2.getPerspectiveTransform(quad.astype(np.float32), dst)
    flat = cv2.warpPerspective(grey, hm, (s, s), flags=cv2.INTER_LINEAR)
    _, bw = cv2.threshold(flat, 0, 255, cv2.THRESH_BINARY | cv2.THRESH_OTSU)
    m = PX_PER_CELL // 4  # each cell's middle half
    cells = bw.reshape(n, PX_PER_CELL, n, PX_PER_CELL)[:, m:-m, :, m:-m]
    return np.asarray(cells.mean(axis=(1, 3)) > 127)


def matches(cells: npt.NDArray[np.bool_], references: list[npt.NDArray[np.bool_]]) -> bool:
    """Whether the cells read are the marker's in a rotation, the covered corner's cells (top left) ignored."""
    seen = np.ones_like(cells)
    seen[:COVERED, :COVERED] = False
    return any(int(np.count_nonzero((cells != r) & seen)) <= MISMATCH_MAX for r in references)


def clockwise(quad: FloatArray) -> FloatArray:
    """The corners in the image's clockwise order (y down), the first kept first."""
    x, y = quad[:, 0], quad[:, 1]
    area = float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    return quad if area > 0 else np.concatenate([quad[:1], quad[:0:-1]])


def _outlines(grey: MatLike, min_side: float, max_shapes: int, more: Callable[[], bool]) -> list[FloatArray]:
    """The outlines (5 to ``MAX_VERTICES`` corners) of the ``max_shapes`` largest dark regions from each threshold
    (``more()`` asked before each: the frame's budget)."""
    out: list[tuple[float, FloatArray]] = []
    for window in THRESH_WINDOWS:
        if not more():
            break
        dark = cv2.adaptiveThreshold(grey, 255, cv2.ADAPTIVE_THRESH_MEAN_C, cv2.THRESH_BINARY_INV, window, THRESH_C)
        for c in cv2.findContours(dark, cv2.RETR_LIST, cv2.CHAIN_APPROX_SIMPLE)[0]:
            if (area := cv2.contourArea(c)) < min_side * min_side:
                continue
            poly = cv2.approxPolyDP(c, APPROX * cv2.arcLength(c, True), True)
            if 5 <= len(poly) <= MAX_VERTICES:
                out.append((area, poly.reshape(-1, 2).astype(np.float64)))
    out.sort(key=lambda p: p[0], reverse=True)
    return [p for _, p in out[:max_shapes]]


def corner_covered_markers(grey: MatLike, references: list[npt.NDArray[np.bool_]], min_side: float,
                           more: Callable[[], bool] = lambda: True, max_shapes: int = 24) -> list[FloatArray]:
    """The markers with one corner covered in ``grey``, as their four corners (the covered one first, clockwise);
    ``more()``: whether time is left to go on."""
    n = references[0].shape[0]
    found: list[FloatArray] = []
    for poly in _outlines(grey, min_side, max_shapes, more):
        if not more():
            break
        for quad in cut_corner_quads(poly):
            if float(np.linalg.norm(quad - np.roll(quad, 1, axis=0), axis=1).min()) < min_side:
                continue  # too few pixels a cell to read
            quad = clockwise(quad)
            if matches(read_cells(grey, quad, n), references):
                found.append(quad)
                break
    return found
