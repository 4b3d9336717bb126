"""The colour-ball detector: every blob of the target's colour, scored on shape, colour purity, isolation and size.

Search, then refine (the cost stays near the floor any colour detector pays, one ``cvtColor`` and one
``inRange`` on the frame):

1. Search: the frame at half resolution (from 320 px wide up; a 16 px target is still 8 px there),
   one ``cvtColor``, one ``inRange``, a 3x3 opening, external contours. The ranges as the fewest ``inRange``
   calls (red in one piece) and the V bound that follows the frame's exposure are ``pilot.vision.hsv.colour``.
2. Refine (refine.py, as are steps 3 and 4): the few largest blobs filling at least ``SEARCH_FILL`` of
   their box's disc are looked at again at full resolution, in a window around each: a 3x3 median (sensor noise
   in a ball's shaded side would fray its outline), mask, 3x3 opening and closing, the blob's contours, and a
   score 0..1 each, a product of ramps each between a value no target shows and one every target shows (chosen
   on the tuning photos of bench/vision); measuring stops as soon as the product so far is below ``hsv.min_score``:

   * shape: the share of the contour lying on its minimum enclosing circle ("arc support": a disk ~1, a
     disk with 30 % hidden behind an edge ~0.7, a square ~0.3) or, where that is low, on an ellipse fitted
     robustly to it (a ball seen through a perspective warp, or with a stub of background attached; its ramp
     is stricter, as an ellipse fits a square's sides better than the enclosing circle does), solidity, fill of
     that circle, and the aspect and fill of its minimum-area rectangle (a rotated bar has a square bounding box; a
     disc fills pi / 4 of its rectangle, a small square blurred round all of it; a blob whose outline keeps to its
     circle may be longer: a ball partly hidden, or with its shaded side out of the mask).
   * colour purity: mean saturation (a small round blob's on its core: blur blends its rim), and how far the
     mean hue sits from the middle of the range (orange and red-brown sit near its edge, the target's red in the
     middle; read without clipped pixels where it holds the score down: an over-exposed red reads orange).
   * isolation: the share of the ring around the circle (1.25 to 1.75 radii, sampled) that is of the
     target's colour: a ball stands apart; a hole in a red poster's print, a piece of a red box or of a brick
     wall does not.
   * size: the range the apparent diameter implies (known diameter, field of view) must be plausible, and
     a blob under 18 px is scored down (too few pixels to show its shape).
   * texture: a blob with round search blobs of its size close around it scores 0 (texture.py).

   The circle, not the blob's centroid, gives the position: a ball's dark side or a covered part moves
   a centroid, not the circle through its rim.
3. Split: a ball in front of something of its colour (a red motorbike, a red-brown saucer) joins it in the
   mask. Unless a candidate already scores ``SPLIT_UNLESS``, the largest search blobs filling less than
   ``SPLIT_FILL`` of their box's disc are split (split.py): by shape, around the widest discs that
   bulge out of them, the mask opened by a disc half as wide (necks go, the ball stays whole; its arcs count
   only on the mask's real edge, as an opened square is round); and by hue, when their pixels fall in two hue
   classes (a ball a few units off a red-brown saucer), each class's round pieces refined in its own range, or
   else by saturation (a crimson ball on a glossy orange-red saucer of its hue), each piece then counting only
   with a rim all round (rim.py) and not in a pattern of round pieces of its size. A search blob that
   measures as a ball there and gave nothing in its window may be joined at full resolution to a strip the
   search's opening took off (a rail, a beam): it is split by shape too, its piece counting only with a full shape
   score (an opening rounds a square's corners; on the dev seeds of bench/vision, 11 balls more of about 7,300,
   none fewer, the same false detections).
4. Edges: a ball on a surface of its colour (a red-brown saucer, a red motorbike's tank) is in one piece with
   it even in hue; if still nothing scores ``SPLIT_UNLESS``, the largest search blobs' windows are cut by the
   image's edges (edges.py) and the round pieces from ``hsv_edges.MIN_SIZE`` measured, isolation
   then being the share of the rim just outside them that is an edge or off the mask.

A frame where nothing scores ``SECOND_LOOK_UNLESS`` gets a second look, steps 1 to 4 with the V bound 0.8 times as
high and the mask grown from it down to ``V_FLOOR`` (``hsv_colour.Grown``), keeping what scores ``SECOND_LOOK_MIN``
(in place of a first measure at its place that scored less): a ball's shaded side, or a ball in dim or back light,
falls below the bound. Grown, on the tuning photos' dev seeds: 30 % hidden balls 88.2 -> 90.9 %, dim 89.2 -> 90.4 %,
none lower, the same false detections in 4,800 empty and distractor views. Its splits (steps 3 and 4) skip the
blobs the first look split or cut and the grown mask left as they were (the same result again): on three dev seed
sets, 0.6-3.1 points more in most conditions (30 % hidden +1.8 / +2.5 / +3.1), the same false detections, the
median frame's time the same, the mean of empty views' 10-25 % more.

A noisy frame (a camera's gain in dim light: noise.py) then gets steps 1 to 4 again on the frame
smoothed, keeping what scores as much: noise frays a dark ball's outline in the mask, and a ball joined to something
of its colour needs the splits there too (with steps 1 and 2 only, on bench/vision's dev seeds of the noise
condition, 4-7 balls fewer of about 165 per photo set, with the same false detections). The laser's aim check reads
such a frame's centre smoothed too.

A frame where nothing scores ``SECOND_LOOK_UNLESS`` after these looks gets a rim look (measure.py): the
blobs that their arcs or ring held down are measured again with their rim support (rim.py), an edge all
round them in brightness (or, short of that, in a colour channel), which stands in for the arcs (a mask frayed by
JPEG's colour blocks, noise or shade) and for isolation (a ball on a surface of its colour). Pieces cut by edges
under ``hsv_edges.MIN_SIZE`` count with a brightness rim of ``hsv_refine.SMALL_RIM``.

A frame where still nothing scores ``SECOND_LOOK_UNLESS`` gets a circle look (circles.py): in the first
look's ``CIRCLE_BLOBS`` largest blobs' windows, circles of brightness edges, then of colour edges (the best of each
octave of radii), with the target's colour inside (one circle to a window: several are a texture of round things, a
flower's petals). A ball on a textured surface of its colour, which even the edges cut into pieces (its shading is
an edge inside it), is one blob with that surface; only its rim tells it apart. A window with no circle whose rim is
whole takes one whose rim is nearly so and whose middle is lit as a ball's (dome.py): JPEG's blocks break
a ball's rim in places. It costs about 2 ms a window, in frames with no ball.

Every look drops the blobs from ``hsv_inside.FROM`` px across that are brightness edges inside (inside.py):
a round texture of the target's colour (a dahlia's heart, its red cups merged by JPEG's blocks), not a plain ball;
and the blobs measured on their rim that are hollow (hollow.py): brighter than their middle, in the
target's colour, further round than a ball lit from one side can be (a dahlia's single cup under blur, whose lit
wall is a brightness edge all round).

A tracked ball the frame's look misses gets a closer look where the track expects it (``candidates_near``, called
by pilot/vision/detect.py): that window refined with the V bound ``NEAR_GAIN`` times as high.

A search blob from ``HALF_TRY`` px across is first measured on the search itself: a plain disc scoring high
there, or any blob from ``HALF_MEASURE`` px, skips the refinement and its fixed cost.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable

import cv2
from cv2.typing import MatLike

from ...common.config import HsvConfig, VisionConfig
from ..detection import Candidate, Detection, best_detection, frame_size, malformed
from .circles import circle_features
from .colour import Bounds, darker, grown
from .hollow import hollow
from .inside import busy_inside
from .measure import HALF_DECIDES
from .noise import smoothed
from .refine import EDGE_BLOBS, SEARCH_FILL, SPLIT_BLOBS, Box, WindowRefiner, is_new
from .score import SIZE, Features, arc_score
from .search import SEARCH_MIN_WIDTH, SearchFrames
from .texture import SearchBlob, textured

log = logging.getLogger(__name__)

MAX_CANDIDATES = 4  # the largest search blobs refined; smaller ones cannot be the nearest target
HALF_MEASURE = 48  # px across (full resolution): a search blob this wide is measured at half resolution
SPLIT_FILL = 0.75  # a search blob filling less of its box's disc may be a ball joined to something
HALF_TRY = 24  # px across: a smaller search blob is only refined; from this, first measured at half
# resolution, where a plain disc scoring HALF_DECIDES (measure.py) skips the refinement
SPLIT_UNLESS = 0.8  # a candidate scoring this already: no split (0.1-0.3 ms a disc or piece refined)
UNREFINED_SHAPE = 1.0  # a piece split off a round search blob that its window did not measure counts only with a
# full shape score (circle or ellipse): the opening that frees a ball from a stub rounds a square's corners too
SECOND_LOOK_UNLESS = 0.6  # nothing scoring this (the default acquisition threshold): a second look...
SECOND_LOOK_GAIN = 0.8  # ...with the V bound this much lower, grown (a ball's shaded side, a dim or backlit ball)...
SECOND_LOOK_MIN = 0.75  # ...keeps what scores this: a fallback needs stronger evidence (tuning photos' empty views)
RIM_LOOKS = 6  # blobs held down by their arcs or ring measured again with their rim, at most
CIRCLE_BLOBS = 2  # the largest search blobs the circle look searches
NEAR_GAIN = 0.4  # a tracked ball's closer look: the V bound this much lower (under the second look's reach)...
NEAR_MARGIN = 0.1  # ...in a window this share of the frame's width wider than the ball on each side
AIM_SPAN, AIM_SHARE = 0.35, 0.8  # the aim point's window (of the ball's diameter), and its share of target colour


def _untried(blobs: list[SearchBlob], tried: set[tuple[float, Box]] | None) -> list[SearchBlob]:
    """The blobs not split or cut already (a grown mask keeps most of them as they were: the same result again)."""
    return blobs if not tried else [b for b in blobs if (b[0], b[2]) not in tried]


class HsvBlobDetector(WindowRefiner):
    name = "hsv"

    def __init__(
        self, config: HsvConfig | None = None, vision: VisionConfig | None = None, fov_deg: float = 60.0,
        clock: Callable[[], float] | None = None,
    ) -> None:
        """``clock``: seconds, for the frame's budget (``vision.budget_ms``; default ``time.perf_counter``)."""
        super().__init__(config or HsvConfig(), vision or VisionConfig(), fov_deg)
        self._blobs: list[SearchBlob] = []  # the first look's search blobs, where the circle look searches
        self._tried: set[tuple[float, Box]] = set()  # the first look's blobs split or cut by edges (area, box)
        self._plain_ok: dict[int, Features] = {}  # this frame's blobs found plain inside (by id, kept alive)
        self._frames = SearchFrames(self.colour)  # the search's frame, HSV and mask, in buffers kept
        if clock is not None:
            self.budget.clock = clock

    @property
    def single_range(self) -> bool:
        """True when the mask costs one cvtColor and one inRange (contiguous hues, shared S/V bounds)."""
        return self.colour.single_range

    def mask(self, image: MatLike) -> MatLike:
        """The full-resolution mask (with the exposure-adapted V bound), as the refinement sees it."""
        return self.colour.mask(image)

    # -- candidates ---------------------------------------------------------------------------------
    def features(self, image: MatLike) -> list[Features]:
        """Every refined blob's features (unscored): a second look with a lower V bound when the first found
        nothing scoring ``SECOND_LOOK_UNLESS``, a smoothed look in a noisy frame, a rim look and a circle look."""
        w = frame_size(image)[0]
        self.budget.start()
        self.new_frame(w)
        self._windows.clear()
        self._plain_ok.clear()
        scale = 2 if w >= SEARCH_MIN_WIDTH else 1
        small, bounds, small_hsv = self._frames.search(image, scale)
        found = self._plain(image, bounds, self._look(image, bounds, small, small_hsv, scale))
        if self._enough(found, w):
            return found
        if (lower := grown(bounds, SECOND_LOOK_GAIN)) is not None:  # not at the floor
            found = self._plain(image, bounds, self._again(image, lower, small, small_hsv, scale, found, splits=True,
                                                   same_frame=True))
            if self._enough(found, w):
                return found
        if (smooth := smoothed(image)) is not None:  # a noisy frame (noise.py)
            s_small, s_bounds, s_hsv = self._frames.search(smooth, scale, look=1)
            found = self._plain(image, bounds, self._again(smooth, s_bounds, s_small, s_hsv, scale, found,
                                                           splits=True))
            if self._enough(found, w):
                return found
        found = self._plain(image, bounds, self._rim_look(found))
        if self._enough(found, w):
            return found
        for f in self._plain(image, bounds, self._circle_look(image, bounds)):
            found = self._with(found, f, self.score(f, w))
        return found

    def _plain(self, image: MatLike, bounds: Bounds, found: list[Features]) -> list[Features]:
        """``found`` without the blobs a candidate could come of that are brightness edges inside, a texture of the
        target's colour (inside.py), or measured on their rim and hollow, a cup of its colour
        (hollow.py, in the colour of ``bounds``): not balls. Checked once each."""
        w = self._width
        out = []
        for f in found:
            if id(f) not in self._plain_ok:
                if self.score(f, w) >= self.cfg.min_score and (
                        busy_inside(image, f.cx, f.cy, f.size)
                        or (f.rim > 0.0 and hollow(image, self.colour, bounds, f.cx, f.cy, f.size))):
                    continue
                self._plain_ok[id(f)] = f
            out.append(f)
        return out

    def _again(self, image: MatLike, bounds: Bounds, small: MatLike, small_hsv: MatLike, scale: int,
               found: list[Features], splits: bool, same_frame: bool = False) -> list[Features]:
        """``found`` and what steps 1 and 2 (with ``splits``, 1 to 4) find once more scoring ``SECOND_LOOK_MIN`` (a
        fallback look); ``same_frame``: on the first look's frame, whose blobs it split or cut are not again. A blob
        measured again replaces its first measure when it scores more: a ball whose shaded side the first look's
        mask left out is whole in the grown one, at the same place (dropped as no new blob until the twenty-fourth
        session: on the five dev seed sets of bench/vision, 33 balls more, 13 of them 30 % hidden, none fewer, the
        same false detections)."""
        self.keep_from = SECOND_LOOK_MIN
        more = self._look(image, bounds, small, small_hsv, scale, splits=splits, first=False,
                          tried=self._tried if same_frame else None)
        for f in more:  # a blob the look measured again, grown or smoothed, replaces its first measure if better
            if (s := self.score(f, self._width)) >= SECOND_LOOK_MIN:
                found = self._with(found, f, s)
        return found

    def _with(self, found: list[Features], f: Features, s: float) -> list[Features]:
        """``found`` with ``f`` (scoring ``s``), which replaces those at its place if it scores more than each and
        none of them is in a pattern of round things (the texture check, texture.py): measured again, a
        dot of a print may read smaller, with fewer peers in reach, and the place stays a pattern."""
        kept: list[Features] = []
        for g in found:
            if is_new(f, [g]):
                kept.append(g)
            elif s <= self.score(g, self._width) or textured(g.cx, g.cy, g.size, self.round_search, self.search_scale):
                return found
        return [*kept, f]

    def _enough(self, found: list[Features], width: int) -> bool:
        """Whether a look found something the pilot would act on, or the frame's time is spent (no further look
        then)."""
        return self.budget.out() or any(self.score(f, width) >= SECOND_LOOK_UNLESS for f in found)

    def _circle_look(self, image: MatLike, bounds: Bounds) -> list[Features]:
        """The circles in the first look's largest blobs' windows (circles.py). ``features`` merges each,
        once checked plain (``_plain``), with ``_with``: it replaces a blob measured at its place if it scores more (a
        ball whose mask JPEG or shade frayed, measured at 0.3-0.6 there, is a circle scoring 0.65-1; until the
        twenty-fourth session the circle was dropped as no new blob; on the five dev seed sets of bench/vision, 7 balls
        more, none fewer, the same false detections)."""
        out: list[Features] = []
        k = self.search_scale
        for _, _, (x, y, bw, bh) in sorted(self._blobs, key=lambda b: b[0], reverse=True)[:CIRCLE_BLOBS]:
            if self.budget.out():
                break
            if max(bw, bh) * k < SIZE[1]:
                continue
            x0, y0, roi, hsv, mask = self._blob_window(image, bounds, (x * k, y * k, bw * k, bh * k))
            out += [f for f in circle_features(roi, hsv, mask, image, x0, y0, self.colour) if is_new(f, out)]
        return out

    def _rim_look(self, found: list[Features]) -> list[Features]:
        """The blobs held down by their arcs or ring measured again with their rim support; each replaces its
        first measure when it scores higher."""
        for d in self.deferred[:RIM_LOOKS]:
            if self.budget.out():
                break
            f = self.measure(d.hsv, d.mask, d.contour, d.area, d.x0, d.y0, d.scale, bgr=d.bgr, rim=True)
            if f is not None and (s := self.score(f, self._width)) >= d.keep_from:
                found = self._with(found, f, s)
        return found

    def _look(self, image: MatLike, bounds: Bounds, small: MatLike, small_hsv: MatLike, scale: int,
              splits: bool = True, first: bool = True,
              tried: set[tuple[float, Box]] | None = None) -> list[Features]:
        """Steps 1 to 4 (without ``splits``, 1 and 2) with ``bounds``, on the search (``small``, ``scale`` x
        smaller, and its HSV); ``first``: the frame's first look, whose blobs the later looks use; ``tried``: blobs
        (area, box) split or cut already, not split or cut again (the first look's, as they are in a grown mask)."""
        w = frame_size(image)[0]
        out: tuple[MatLike | None, ...] = self._frames.mask_buffers(frame_size(small_hsv)) if first else (None, None)
        mask = self.colour.in_range(small_hsv, bounds, out[0])
        if self.colour.kernel is not None:
            mask = cv2.morphologyEx(mask, cv2.MORPH_OPEN, self.colour.kernel, dst=out[1])
        # every point kept: a blob measured on the search needs them for its arcs
        contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
        min_area = self.cfg.min_area / (scale * scale)
        boxes: list[SearchBlob] = []
        joined: list[SearchBlob] = []
        blobs: list[SearchBlob] = []
        for c in contours:
            if len(c) < 6 or (area := cv2.contourArea(c)) < min_area:
                continue
            x, y, bw, bh = cv2.boundingRect(c)
            box = (x, y, bw, bh)
            blobs.append((area, c, box))
            disc = math.pi * (max(bw, bh) / 2.0) ** 2
            # a blob filling less than SEARCH_FILL of its box's disc cannot hold a ball the refinement would take
            if area >= SEARCH_FILL * disc:
                boxes.append((area, c, box))
            if area < SPLIT_FILL * disc:
                joined.append((area, c, box))
        boxes.sort(key=lambda b: b[0], reverse=True)
        if first:  # the first look's blobs: where the circle look would search, and the round ones a texture
            self._blobs, self.round_search, self.search_scale = blobs, boxes, scale
            self._tried.clear()
        found: list[Features] = []
        unrefined: list[SearchBlob] = []  # balls in the search, nothing measured in their windows
        for i, (area, c, (x, y, bw, bh)) in enumerate(boxes[:MAX_CANDIDATES]):
            if i and self.budget.out():  # the largest blob is always measured: the best candidate so far
                break
            across = max(bw, bh) * scale if scale > 1 else 0  # searched at full resolution: refined as it is
            # below HALF_MEASURE, the look at half resolution counts only if it decides (and stops when it cannot)
            decide = across < HALF_MEASURE
            half = self.measure(small_hsv, mask, c, area, 0, 0, scale, decide=decide,
                                bgr=small) if across >= HALF_TRY else None
            if not decide:
                fs = [] if half is None else [half]
            elif half is not None and self.score(half, w) >= HALF_DECIDES:
                fs = [half]
            else:
                fs = self._refine(image, bounds, (x * scale, y * scale, bw * scale, bh * scale))
                # a ball in the search, joined in its window? (``half``, stricter, says so where it measured one)
                if not fs and scale > 1 and (half is not None
                                             or self.measure(small_hsv, mask, c, area, 0, 0, scale) is not None):
                    unrefined.append((area, c, (x, y, bw, bh)))
            found += [f for f in fs if is_new(f, found)]
        good = not splits or self.budget.out() or any(self.score(f, w) >= SPLIT_UNLESS for f in found)
        if (joined or unrefined) and not good:
            joined.sort(key=lambda b: b[0], reverse=True)
            joined, unrefined = _untried(joined[:SPLIT_BLOBS], tried), _untried(unrefined, tried)
            if first:
                self._tried.update((a, box) for a, _, box in joined + unrefined)
            split = self._split(image, bounds, joined, scale, found)
            split += [f for f in self._split(image, bounds, unrefined, scale, found + split)
                      if arc_score(f.arc, f.ellipse_arc) >= UNREFINED_SHAPE]
            if len(bounds) == 1:
                split += self._colour_split(image, bounds, small_hsv, mask, joined, scale, found + split)
            found += split
            good = any(self.score(f, w) >= SPLIT_UNLESS for f in split)
        if blobs and not good and not self.budget.out():
            # any blob: a ball with a stub of a saucer on it can fill its box like a ball, and score too low
            blobs.sort(key=lambda b: b[0], reverse=True)
            blobs = _untried(blobs[:EDGE_BLOBS], tried)
            if first:
                self._tried.update((a, box) for a, _, box in blobs)
            found += self._edge_split(image, bounds, blobs, scale, found)
        return found

    def candidates(self, image: MatLike) -> list[Candidate]:
        """Every candidate, best first; an empty list for a frame ``detection.malformed`` names (no OpenCV error)."""
        if malformed(image) is not None:
            return []
        found = self._ranked(self.features(image), frame_size(image)[0])
        if self.budget.exhausted:
            log.info("hsv: frame budget of %.1f ms spent (%.1f ms): the best candidate so far kept",
                     self.budget.budget_ms, self.budget.spent_ms())
        return found

    @property
    def cut_short(self) -> bool:
        """Whether the last frame's look stopped at the frame's budget (``vision.budget_ms``)."""
        return self.budget.exhausted

    def _ranked(self, found: list[Features], width: int) -> list[Candidate]:
        """The blobs scoring above zero and at least ``min_score``, as candidates, best first."""
        out = [Candidate(f.cx, f.cy, f.size, s) for f in found if (s := self.score(f, width)) > 0.0
               and s >= self.cfg.min_score]
        return sorted(out, key=lambda c: c.score, reverse=True)

    def candidates_near(self, image: MatLike, cx: float, cy: float, size: float) -> list[Candidate]:
        """Where a tracked ball should be and the frame's look found nothing: that window refined with the V
        bound ``NEAR_GAIN`` times as high. The frame's bound follows its brightest part: a ball against a
        bright window darkens under it as the window fills more of the frame, while still plainly a red disc."""
        if malformed(image) is not None or self.budget.out():  # the frame's time is spent: no closer look
            return []
        w, h = frame_size(image)
        self._width = w
        half = size / 2.0 + NEAR_MARGIN * w
        x0, y0 = max(0, int(cx - half)), max(0, int(cy - half))
        x1, y1 = min(w, int(cx + half) + 1), min(h, int(cy + half) + 1)
        if x1 - x0 < 2 or y1 - y0 < 2:
            return []
        near = darker(self.colour.bounds_for(image), NEAR_GAIN)
        found = self._refine(image, near, (x0, y0, x1 - x0, y1 - y0))
        return self._ranked(self._plain(image, near, found), w)

    def detect(self, image: MatLike) -> Detection:
        """This frame alone, the best candidate (no tracking, no frame checks)."""
        return best_detection(self, image, self.cfg.target_diameter_m, self.fov_deg)

    def aim_on_target(self, image: MatLike, size: float) -> bool:
        """Whether the laser's aim point (the frame's centre) shows the target's colour, in a window a third of
        the ball across: something in front of a centred ball hides its middle while the circle fitted to its
        rim stays centred, and it reaches the window's edge a frame or two before the middle. The V bound is the
        closer look's (``NEAR_GAIN``): the ball it found in shade is in shade at its middle too."""
        if malformed(image) is not None:
            return False
        r = max(2, min(round(AIM_SPAN * size / 2.0), image.shape[0] // 4))
        return self.colour.centre_holds(image, r, NEAR_GAIN, AIM_SHARE)
