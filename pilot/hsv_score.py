"""What the colour-ball detector measures of a blob, and the ramps that score it (pilot/hsv.py)."""

from __future__ import annotations

from typing import NamedTuple

# score ramps (zero, one), set on the tuning photos only (bench/vision/RESULTS.md)
ARC = (0.3, 0.6)
ARC_TOL = 0.12  # a contour point within this share of the radius (at least 1.5 px) lies on the circle
ELLIPSE_ARC = (0.7, 0.9)  # the share on the fitted ellipse (pilot/hsv_shape.py): squares reach 0.5-0.8
SOLIDITY = (0.7, 0.88)
FILL = (0.35, 0.6)
ELONGATION = (2.0, 1.4)  # minimum-area rectangle, longer side over shorter (falling ramp)
SATURATION = (10.0, 60.0)  # mean saturation above the S bound (pink and pale red sit just over it)
HUE_OFF = (0.6, 1.0)  # mean hue's distance from the range's middle, in half-widths
RING = (0.35, 0.1)  # share of the ring of the target's colour (falling ramp)
RIM = (0.65, 0.85)  # the rim's share that is a brightness edge (pilot/hsv_rim.py): a ball's is 0.8-1.0 whatever
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
    saturation: float  # mean, 0..255
    hue_off: float  # mean hue's distance from the range's middle, in half-widths
    ring: float  # the ring's share of the target's colour (a piece cut by edges: its rim's share not walled in)
    ellipse_arc: float  # 0 where the circle's arc was enough (it is measured only below ARC's one)
    rim: float  # the rim support (pilot/hsv_rim.py), 0 unless measured (the rim and circle looks, small edge pieces)


def ramp(value: float, zero: float, one: float) -> float:
    v = (value - zero) / (one - zero)  # compared, not clamped with min/max: about 40 calls a frame
    return 0.0 if v <= 0.0 else 1.0 if v >= 1.0 else v


def arc_score(arc: float, ellipse_arc: float) -> float:
    return max(ramp(arc, *ARC), ramp(ellipse_arc, *ELLIPSE_ARC))
