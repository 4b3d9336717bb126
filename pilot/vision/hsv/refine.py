"""The full-resolution work of the colour-ball detector (detector.py): a search blob's window refined (step 2),
and the blobs that join a ball to something of its colour split by shape, by hue and by the image's edges (steps 3
and 4). detector.py's docstring tells what each step is for and when it runs."""

from __future__ import annotations

import cv2
import numpy as np
from cv2.typing import MatLike

from ...common.config import HsvConfig, VisionConfig
from ..detection import frame_size
from .colour import Bounds
from .edges import MIN_SIZE, WALL_GROWTH, cut_by_edges, walled_in
from .measure import BlobMeasure
from .rim import WHOLE, rim_support
from .score import SIZE, Features
from .split import HUE, colour_pieces, disc_centres, split_off
from .texture import SearchBlob

SEARCH_FILL = 0.45  # below FILL's zero: the search's coarser outline never rejects what the refinement keeps; a
# piece split off filling less of its box's disc is not measured either
BLOBS_PER_BOX = 2  # blobs measured in one search blob's window (noise can join two at half resolution)
SPLIT_BLOBS = 3  # the largest joined blobs searched for discs
SPLIT_PEAKS = 4  # disc centres refined per frame, widest first
EDGE_BLOBS = 2  # the largest search blobs cut by the image's edges
SMALL_RIM = 0.85  # a piece cut by edges under MIN_SIZE counts with this rim support (not texture)
BLOB_PAD = 4  # px: a search blob's window for the edges and the circle look is this much wider on each side

Box = tuple[int, int, int, int]  # x, y, width, height


def is_new(f: Features, found: list[Features]) -> bool:
    """Not within a pixel of one already found (windows overlap; the splits find blobs the search found)."""
    return all(abs(f.cx - g.cx) > 1.0 or abs(f.cy - g.cy) > 1.0 for g in found)


class WindowRefiner(BlobMeasure):
    """Blobs measured at full resolution in windows of the frame, each window's pixels, HSV and mask made once a
    frame for the blob windows that several steps search."""

    def __init__(self, cfg: HsvConfig, vision: VisionConfig, fov_deg: float) -> None:
        super().__init__(cfg, vision, fov_deg)
        self._windows: dict[Box, tuple[Bounds, MatLike, MatLike, MatLike]] = {}  # this frame's blob windows

    def _edge_split(self, image: MatLike, bounds: Bounds, blobs: list[SearchBlob],
                    scale: int, found: list[Features]) -> list[Features]:
        """Balls on a surface of their colour: the largest search blobs' windows cut by the image's edges, the
        round pieces measured alone, their ring replaced by the share of their rim not walled in."""
        out: list[Features] = []
        for _, _, (x, y, bw, bh) in blobs[:EDGE_BLOBS]:
            if max(bw, bh) * scale < MIN_SIZE or self.budget.out():
                continue
            x0, y0, roi, hsv, mask = self._blob_window(image, bounds, (x * scale, y * scale, bw * scale, bh * scale))
            cut = cut_by_edges(roi, mask, self.colour.kernel, self.cfg.min_area, SEARCH_FILL)
            for c, area in cut.pieces:
                if self.budget.out():  # each piece's measure is a ring, a rim and more: up to 4 ms a window
                    break
                piece = np.zeros_like(np.asarray(mask))
                cv2.drawContours(piece, [c], -1, 255, -1)
                f = self.measure(hsv, piece, c, area, x0, y0)
                if f is None:
                    continue
                f = f._replace(size=f.size + WALL_GROWTH, ring=1.0 - walled_in(cut.separated, c))
                if SIZE[1] <= f.size < MIN_SIZE:  # a small piece: a bit of texture unless a brightness edge all round
                    f = f._replace(rim=rim_support(roi, f.cx - x0, f.cy - y0, (f.size - 1.0) / 2.0))
                if (f.size >= MIN_SIZE or (f.size >= SIZE[1] and f.rim >= SMALL_RIM)) and is_new(f, found + out):
                    out.append(f)
        return out

    def _colour_split(self, image: MatLike, bounds: Bounds, hsv: MatLike, mask: MatLike,
                      joined: list[SearchBlob], scale: int, found: list[Features]) -> list[Features]:
        """Balls a few hue units off what they are joined to (a red ball on a red-brown saucer), or of the same hue
        and less or more saturated: the round pieces of each class of the largest joined blobs (split.py),
        refined in that class's range (their rings then see only their own class). One range only
        (colour.py). A piece split by saturation counts only with a rim all round (``WHOLE``, in
        brightness or colour), from ``SIZE``'s full size (18 px) as a piece cut by edges: a surface's shading and
        gloss vary its saturation in patches, a ball differs from it at its outline. It is not deferred to the rim
        look (its rim is read here), and keeps its rim, which the hollow check reads (a cup's wall is a rim too)."""
        min_area = self.cfg.min_area / (scale * scale)
        out: list[Features] = []
        for sub, (px, py, pw, ph), channel in colour_pieces(hsv, mask, joined[:SPLIT_BLOBS], bounds, min_area,
                                                            SEARCH_FILL, self.colour.clean):
            if self.budget.out():
                break
            box = (px * scale, py * scale, pw * scale, ph * scale)
            if channel == HUE:
                out += [f for f in self._refine(image, sub, box) if is_new(f, found + out)]
                continue
            deferred = len(self.deferred)
            pieces = self._refine(image, sub, box)
            del self.deferred[deferred:]
            for f in pieces:
                if f.size < SIZE[1] or not is_new(f, found + out):
                    continue
                rim = rim_support(image, f.cx, f.cy, (f.size - 1.0) / 2.0, colour=True)
                if rim >= WHOLE:
                    out.append(f._replace(rim=rim))
        return out

    def _split(self, image: MatLike, bounds: Bounds, joined: list[SearchBlob],
               scale: int, found: list[Features]) -> list[Features]:
        """Balls joined to something of their colour: the widest discs of the largest joined blobs, refined."""
        centres = sorted((p for _, c, box in joined[:SPLIT_BLOBS] for p in disc_centres(c, box)), reverse=True)
        out: list[Features] = []
        half = (scale - 1) / 2.0
        for r, px, py in centres[:SPLIT_PEAKS]:
            if self.budget.out():
                break
            f = self._refine_disc(image, bounds, px * scale + half, py * scale + half, r * scale)
            if f is not None and is_new(f, found + out):
                out.append(f)
        return out

    def _blob_window(self, image: MatLike, bounds: Bounds, box: Box) -> tuple[int, int, MatLike, MatLike, MatLike]:
        """A search blob's window (``BLOB_PAD`` wider), its corner, pixels, HSV and mask; remembered for the frame:
        the edges and the circle look search the same blobs with the same bounds."""
        w, h = frame_size(image)
        x, y, bw, bh = box
        x0, y0 = max(0, x - BLOB_PAD), max(0, y - BLOB_PAD)
        key = (x0, y0, min(w, x + bw + BLOB_PAD), min(h, y + bh + BLOB_PAD))
        known = self._windows.get(key)
        if known is None or known[0] is not bounds:
            known = (bounds, *self._window(image, bounds, *key))
            self._windows[key] = known
        return x0, y0, known[1], known[2], known[3]

    def _window(self, image: MatLike, bounds: Bounds, x0: int, y0: int, x1: int,
                y1: int) -> tuple[MatLike, MatLike, MatLike]:
        """The window's smoothed pixels, their HSV and the cleaned mask."""
        # smoothed: sensor noise in a ball's shaded side would fray its outline and the shape with it
        roi = cv2.medianBlur(image[y0:y1, x0:x1], 3)  # a view: OpenCV reads its rows in place
        hsv = cv2.cvtColor(roi, self.colour.code)
        return roi, hsv, self.colour.clean(self.colour.in_range(hsv, bounds))

    def _refine(self, image: MatLike, bounds: Bounds, box: Box) -> list[Features]:
        """The blobs of a search box at full resolution (a search blob may be several joined by noise), in a
        window that also holds their rings."""
        w, h = frame_size(image)
        bx, by, bw, bh = box
        pad = max(bw, bh) // 2 + 4  # a ring reaches 1.75 radii; the search rounds by a pixel or two
        x0, y0 = max(0, bx - pad), max(0, by - pad)
        roi, hsv, mask = self._window(image, bounds, x0, y0, min(w, bx + bw + pad), min(h, by + bh + pad))
        contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
        blobs = [(a, c) for c in contours if len(c) >= 8 and (a := float(cv2.contourArea(c))) >= self.cfg.min_area]
        blobs.sort(key=lambda b: b[0], reverse=True)
        found = (self.measure(hsv, mask, c, area, x0, y0, bgr=roi) for area, c in blobs[:BLOBS_PER_BOX])
        return [f for f in found if f is not None]

    def _refine_disc(self, image: MatLike, bounds: Bounds, px: float, py: float, r: float) -> Features | None:
        """The piece of the mask around a disc centre that an opening leaves (split.py), measured."""
        w, h = frame_size(image)
        pad = int(2.0 * r) + 6  # the ring reaches 1.75 radii
        cx, cy = int(px), int(py)
        x0, y0 = max(0, cx - pad), max(0, cy - pad)
        _, hsv, mask = self._window(image, bounds, x0, y0, min(w, cx + pad + 1), min(h, cy + pad + 1))
        piece = split_off(mask, cx - x0, cy - y0, r, self.cfg.min_area)
        if piece is None:
            return None
        # the ring on the unopened mask: what the opening cut off is still around the ball
        f = self.measure(hsv, mask, piece.contour, piece.area, x0, y0, cut=True)
        # the widest disc gives the position and size (a drawn disc 2 R + 1 px across reads R at its centre)
        return None if f is None else f._replace(cx=piece.cx + x0, cy=piece.cy + y0, size=2.0 * piece.radius + 1.0)
