"""What the colour-ball detector measures of a blob, and the ramps that score it (detector.py)."""

from __future__ import annotations

from typing import NamedTuple

# score ramps (zero, one), set on the tuning photos only (bench/vision/RESULTS.md)
ARC = (0.3, 0.6)
ARC_TOL = 0.12  # a contour point within this share of the radius (at least 1.5 px) lies on the circle
ELLIPSE_ARC = (0.7, 0.9)  # the share on the fitted ellipse (shape.py): squares reach 0.5-0.8
SOLIDITY = (0.7, 0.88)
FILL = (0.35, 0.6)
ELONGATION = (2.0, 1.4)  # minimum-area rectangle, longer side over shorter (falling ramp)
ELONGATION_ROUND = (2.4, 1.7)  # ...for a blob whose arcs score fully (ARC's one): a ball 30 % hidden, or with its
# shaded side out of the mask, is 1.6 long, and its outline keeps to its circle while a bar's does not (dev seeds: 11
# balls more of 3,400 on the tuning photos, 9 of them 30 % occluded, 4 occluded of 800 on the validation photos; the
# same false detections in 9,600 and 2,400 views; from an arc of 0.55 or 0.5, 1 or 3 red shapes more)
BOX_FILL = (0.96, 0.87)  # area over the minimum-area rectangle's (falling ramp): a disc, an ellipse, a disc with a
# side cut off fill pi / 4 of it (balls on the tuning photos' dev seeds: 0.84-0.88 at the 99th percentile), a square
# or a bar all of it. A small square blurred round reached 1.0 before (its arcs fit the enclosing circle): on the dev
# seeds, red shapes with a detection 12 -> 9 of 480 views, 1 ball fewer of 3,400 (JPEG's colour blocks square a small
# ball off); from (0.94, 0.86), 8 of 480 for 5 balls
BOX_FILL_FROM = 14.0  # px across: the mask's 3x3 opening squares a smaller blob off (a digital disc 13 px across fills
# 0.92 of its rectangle, 14 px 0.88)
SATURATION = (10.0, 60.0)  # mean saturation above the S bound (pink and pale red sit just over it)
HUE_OFF = (0.6, 1.0)  # mean hue's distance from the range's middle, in half-widths
RING = (0.35, 0.1)  # share of the ring of the target's colour (falling ramp)
RIM = (0.65, 0.85)  # the rim's share that is a brightness edge (rim.py): a ball's is 0.8-1.0 whatever
# its mask (0.7-0.9 found 1-2 JPEG or noisy balls fewer per 80 on the tuning photos' dev seeds, with the same
# false detections in 3,600 empty and distractor views)
SIZE = (10.0, 18.0)  # diameter, pixels: a smaller blob has too few pixels to show its shape (from (8, 16): on the
# tuning photos' dev seeds, 4 of 2,400 empty views with a detection instead of 10, 20 of 2,400 distractor views
# instead of 27, and 4 balls fewer of 1,500)


class Features(NamedTuple):
    """What the score of one blob is made of (bench/vision tunes the ramps on these)."""

    cx: float
    cy: float
    size: float  # diameter of the fitted circle, pixels
    arc: float
    solidity: float
    fill: float
    elongation: float
    box_fill: float  # area over the minimum-area rectangle's (a circle look's circle: pi / 4, a disc's)
    saturation: float  # mean, 0..255
    hue_off: float  # mean hue's distance from the range's middle, in half-widths
    ring: float  # the ring's share of the target's colour (a piece cut by edges: its rim's share not walled in)
    ellipse_arc: float  # 0 where the circle's arc was enough (it is measured only below ARC's one)
    rim: float  # the rim support (rim.py), 0 unless measured (the rim and circle looks, small edge pieces)
    domed: bool = False  # a circle look's circle taken for its middle lit as a ball's (dome.py): its rim,
    # short of a whole one, counts as whole


def ramp(value: float, zero: float, one: float) -> float:
    v = (value - zero) / (one - zero)  # compared, not clamped with min/max: about 40 calls a frame
    return 0.0 if v <= 0.0 else 1.0 if v >= 1.0 else v


def stretch_score(elongation: float, arc: float) -> float:
    """The minimum-area rectangle's aspect: a blob whose outline keeps to its circle (arcs scoring fully) may be
    longer."""
    return ramp(elongation, *(ELONGATION_ROUND if arc >= ARC[1] else ELONGATION))


def box_score(box_fill: float, size: float) -> float:
    """The minimum-area rectangle's fill: a blob under ``BOX_FILL_FROM`` fills its rectangle whatever its shape."""
    return ramp(box_fill, *BOX_FILL) if size >= BOX_FILL_FROM else 1.0


def arc_score(arc: float, ellipse_arc: float) -> float:
    return max(ramp(arc, *ARC), ramp(ellipse_arc, *ELLIPSE_ARC))
