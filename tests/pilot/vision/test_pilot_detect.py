from __future__ import annotations

import itertools

import cv2
import numpy as np
import pilot_synth as synth
import pytest

from pilot.common.config import ArucoConfig, HsvConfig
from pilot.vision.detect import ArucoMarkerDetector, HsvBlobDetector
from pilot.vision.hsv import detector as hsv

SIZES = [(320, 240), (640, 480)]


@pytest.mark.parametrize("width,height", SIZES)
@pytest.mark.parametrize("gain,noise", [(1.0, 0.0), (0.6, 0.0), (1.3, 0.0), (1.0, 8.0), (0.7, 6.0)])
def test_hsv_position_and_size_across_frame(width: int, height: int, gain: float, noise: float) -> None:
    det = HsvBlobDetector(HsvConfig())
    bg = synth.background(width, height)
    checked = 0
    for fx, fy, radius in itertools.product((0.15, 0.5, 0.85), (0.2, 0.5, 0.8), (5, 12, 30)):
        cx, cy = int(fx * width), int(fy * height)
        img = synth.red_disc(bg, cx, cy, radius, gain, noise, seed=checked)
        d = det.detect(img)
        assert d.found, (cx, cy, radius, gain, noise)
        assert abs(d.cx - cx) <= 1.5 and abs(d.cy - cy) <= 1.5, (d, cx, cy)
        assert abs(d.size - 2 * radius) <= 3.0, (d.size, radius)
        # a blob under 18 px is scored down on purpose (too few pixels to show its shape: bench/vision)
        assert d.confidence > (0.85 if radius >= 12 else 0.15)
        assert (d.width, d.height) == (width, height)
        checked += 1
    assert checked == 27


def test_hsv_picks_largest_red_blob_and_ignores_speckle() -> None:
    det = HsvBlobDetector(HsvConfig())
    img = synth.background(320, 240)
    cv2.circle(img, (60, 60), 8, synth.RED, -1)
    cv2.circle(img, (200, 150), 20, synth.RED, -1)
    img[10, 300] = synth.RED  # single pixel: removed by the opening
    d = det.detect(img)
    assert d.found and abs(d.cx - 200) <= 1 and abs(d.cy - 150) <= 1


def test_hsv_min_area() -> None:
    det = HsvBlobDetector(HsvConfig(min_area=200))
    bg = synth.background(320, 240)
    assert not det.detect(synth.red_disc(bg, 100, 100, 5)).found  # area ~78 < 200
    assert det.detect(synth.red_disc(bg, 100, 100, 10)).found


@pytest.mark.parametrize("width,height", SIZES)
@pytest.mark.parametrize("gain", [0.6, 1.0, 1.3])
def test_hsv_no_detection_with_only_distractors(width: int, height: int, gain: float) -> None:
    det = HsvBlobDetector(HsvConfig())
    img = synth.background(width, height)
    for i, colour in enumerate(synth.DISTRACTORS.values()):
        cv2.circle(img, (40 + i * (width // 6), height // 2), width // 16, colour, -1)
        cv2.rectangle(img, (20 + i * (width // 6), 10), (50 + i * (width // 6), 40), colour, -1)
    img = synth.degrade(img, gain, 6.0, seed=3)
    d = det.detect(img)
    assert not d.found, d


@pytest.mark.parametrize("width,height", SIZES)
def test_hsv_ball_joined_to_something_red_is_split_off(width: int, height: int) -> None:
    """A ball overlapping a red bar (a red motorbike's frame behind it) is no disc in the mask; the split (the
    widest disc in the joined blob, the mask opened around it) gives it back, centred; the bar alone is no ball.
    The smaller ball's neck is wider for its size: shoulders of the bar stay on it and score it down."""
    s = width // 320
    bar = synth.background(width, height)
    cv2.rectangle(bar, (40 * s, 100 * s), (280 * s, 108 * s), synth.RED, -1)
    assert not HsvBlobDetector(HsvConfig()).detect(bar).found
    for cx, cy, r, least in ((160, 128, 22, 0.6), (90, 88, 14, 0.3)):  # below the bar; above it, at its left
        img = synth.red_disc(bar, cx * s, cy * s, r * s)
        d = HsvBlobDetector(HsvConfig()).detect(img)
        assert d.found and d.confidence >= least, (cx, cy, d)
        assert abs(d.cx - cx * s) <= 1.5 * s and abs(d.cy - cy * s) <= 1.5 * s, (cx, cy, d)
        assert abs(d.size - 2 * r * s) <= 3.0 * s, (cx, cy, d)


SAUCER = (20, 30, 120)  # BGR: a dark red-brown, about 3 hue units off the ball's red (too close to split by hue)


@pytest.mark.parametrize("cx,cy,r", [(150, 120, 24), (100, 100, 14), (210, 140, 40)])
def test_hsv_ball_on_a_surface_of_its_colour_is_cut_free_by_its_edges(cx: int, cy: int, r: int) -> None:
    """A ball lying on a red-brown saucer is one blob with it in the mask, and its ring is of the target's colour;
    the image's edges wall it in all round, and it is found, centred, its size right. The saucer alone is none."""
    saucer = synth.background(320, 240)
    cv2.ellipse(saucer, (160, 120), (150, 110), 0.0, 0.0, 360.0, SAUCER, -1, cv2.LINE_AA)
    assert not HsvBlobDetector(HsvConfig()).detect(saucer).found
    d = HsvBlobDetector(HsvConfig()).detect(synth.red_disc(saucer, cx, cy, r, noise=3.0))
    assert d.found and d.confidence >= 0.6, d
    assert abs(d.cx - cx) <= 1.5 and abs(d.cy - cy) <= 1.5 and abs(d.size - (2 * r + 1)) <= 3.0, d


def test_hsv_dark_ball_gets_a_second_look(monkeypatch: pytest.MonkeyPatch) -> None:
    """A ball a little darker than the mask's V bound (a bright window elsewhere keeps the exposure's bound up) is
    not in the first look's mask; the second look, with the bound lower, finds it."""
    img = synth.background(320, 240)
    img[:40, :60] = 250  # the bright window
    dark = cv2.cvtColor(np.array([[[0, 210, 62]]], np.uint8), cv2.COLOR_HSV2BGR)[0, 0]  # V 62, below 70
    cv2.circle(img, (170, 130), 22, tuple(int(v) for v in dark), -1, cv2.LINE_AA)
    d = HsvBlobDetector(HsvConfig()).detect(img)
    assert d.found and d.confidence >= 0.6 and abs(d.cx - 170) <= 1.5 and abs(d.cy - 130) <= 1.5, d
    monkeypatch.setattr(hsv, "grown", lambda bounds, gain: None)  # no second look
    assert not HsvBlobDetector(HsvConfig()).detect(img).found


@pytest.mark.parametrize("r", [20, 30])
def test_hsv_second_look_grows_a_ball_into_its_shaded_side(monkeypatch: pytest.MonkeyPatch, r: int) -> None:
    """A ball lit from the upper left with its lit left third hidden: what is left over the V bound is a sliver of
    it; its shaded side, under the bound, touches the sliver, and the second look's mask grows into it (the
    ``Grown`` bounds of pilot/vision/hsv/colour.py): the ball whole, centred, its size right. Without the second look it
    scores under the acquisition threshold."""
    bg = synth.background(320, 240).astype(np.float64)
    bg[:40, :60] = 250  # a bright window keeps the V bound up
    img = synth.matte_ball(bg, 170, 130, r, (40, 40, 230), 0.2)
    x = int(170 - r + 0.6 * r)
    img[:, :x] = bg[:, :x]  # the hiding thing: a grey edge
    img[:, x - 4: x] = 90
    frame = np.clip(img, 0, 255).astype(np.uint8)
    d = HsvBlobDetector(HsvConfig()).detect(frame)
    assert d.found and d.confidence >= 0.6, d
    assert abs(d.cx - 170) <= 1.5 and abs(d.cy - 130) <= 1.5 and abs(d.size - (2 * r + 1)) <= 3.0, d
    monkeypatch.setattr(hsv, "grown", lambda bounds, gain: None)
    assert HsvBlobDetector(HsvConfig()).detect(frame).confidence < 0.6


def test_hsv_red_surface_cut_by_its_texture_is_no_ball() -> None:
    """Texture edges cut a red surface into bits; some are round enough, but small (pilot/hsv_edges.MIN_SIZE) or
    walled in only in part, and none is taken for the ball."""
    rng = np.random.default_rng(5)
    for _ in range(20):
        img = synth.background(320, 240)
        cv2.rectangle(img, (30, 20), (290, 220), SAUCER, -1)
        for _ in range(int(rng.integers(8, 30))):
            p, q = rng.integers((30, 20), (290, 220), (2, 2))
            cv2.line(img, tuple(int(v) for v in p), tuple(int(v) for v in q), (20, 25, 70), int(rng.integers(1, 4)))
        d = HsvBlobDetector(HsvConfig()).detect(synth.degrade(img, 1.0, 3.0, seed=int(rng.integers(99))))
        assert not d.found or d.confidence < 0.6, d


@pytest.mark.parametrize("axes", [(20, 16), (30, 23), (12, 10)])
def test_hsv_ball_seen_at_an_angle_is_acquired(axes: tuple[int, int]) -> None:
    """A ball through a perspective warp is an ellipse: its enclosing circle misses most of its outline, a fitted
    ellipse does not."""
    img = synth.background(320, 240)
    cv2.ellipse(img, (150, 110), axes, 30.0, 0.0, 360.0, synth.RED, -1, cv2.LINE_AA)
    d = HsvBlobDetector(HsvConfig()).detect(img)
    assert d.found and d.confidence >= 0.6, d
    assert abs(d.cx - 150) <= 1.5 and abs(d.cy - 110) <= 1.5, d


@pytest.mark.parametrize("angle", [0.0, 20.0, 45.0])
def test_hsv_red_square_is_no_ball(angle: float) -> None:
    img = synth.background(320, 240)
    box = cv2.boxPoints(((160.0, 120.0), (30.0, 30.0), angle))
    cv2.fillPoly(img, [np.round(box).astype(np.int32)], synth.RED, cv2.LINE_AA)
    d = HsvBlobDetector(HsvConfig()).detect(img)
    assert not d.found or d.confidence < 0.6, d


@pytest.mark.parametrize("side,blur", [(16, 1.5), (18, 1.0), (20, 0.0), (20, 1.0), (24, 1.5)])
@pytest.mark.parametrize("disc", [False, True])
def test_hsv_small_square_blurred_round_is_no_ball_and_a_disc_is(side: int, blur: float, disc: bool) -> None:
    """A small square at 45 degrees, blurred, fits its enclosing circle as well as a disc does (each of these scored
    0.7-1.0 before the fill of its minimum-area rectangle was scored); a disc as wide, blurred alike, still scores 1."""
    img = synth.background(320, 240)
    if disc:
        cv2.circle(img, (160 * 16, 120 * 16), side * 8, synth.RED, -1, cv2.LINE_AA, 4)
    else:
        box = cv2.boxPoints(((160.0, 120.0), (float(side), float(side)), 45.0))
        cv2.fillPoly(img, [np.round(box * 16).astype(np.int32)], synth.RED, cv2.LINE_AA, 4)
    if blur:
        img = np.asarray(cv2.GaussianBlur(img, (0, 0), blur), np.uint8)
    d = HsvBlobDetector(HsvConfig()).detect(img)
    if disc:
        assert d.found and d.confidence >= 0.95, d
    else:
        assert not d.found or d.confidence < 0.6, d


@pytest.mark.parametrize("r", [20, 30])
@pytest.mark.parametrize("side", [0.0, 60.0, 135.0, 200.0])
def test_hsv_ball_partly_hidden_is_as_long_as_it_needs_to_be(r: int, side: float) -> None:
    """A shaded ball with 30 % of it behind a grey object is 1.6 times longer than wide, and its outline keeps to its
    circle: scored as a ball (0.74-0.83 when every blob 1.4 long or more was scored down)."""
    ball = synth.matte_ball(synth.background(320, 240).astype(np.float64), 160.0, 120.0, r, (40.0, 40.0, 210.0), 0.6)
    ux, uy = np.cos(np.radians(side)), np.sin(np.radians(side))
    yy, xx = np.mgrid[0:240, 0:320]
    along, across = (xx - 160) * ux + (yy - 120) * uy, (xx - 160) * uy - (yy - 120) * ux
    ball[(along >= 0.325 * r) & (np.abs(across) <= 1.6 * r)] = (90.0, 100.0, 95.0)  # a chord 0.325 r out: 30 %
    d = HsvBlobDetector(HsvConfig()).detect(np.clip(ball, 0, 255).astype(np.uint8))
    assert d.found and d.confidence >= 0.9, d
    assert abs(d.cx - 160.0) <= 2.0 and abs(d.cy - 120.0) <= 2.0, d


@pytest.mark.parametrize(
    "hue,sat,lo,hi",
    [
        (0, 210, 0.95, 1.0),  # the range's middle, saturated
        (4, 210, 0.6, 0.95),  # two thirds out to the range's edge: scored down, still acquired
        (176, 210, 0.6, 0.95),
        (4, 150, 0.0, 0.6),  # off-middle and pale (pink, faded red): not acquired
        (0, 135, 0.0, 0.2),  # just over the saturation bound: not reported
    ],
)
def test_hsv_colour_purity(hue: int, sat: int, lo: float, hi: float) -> None:
    bgr = cv2.cvtColor(np.array([[[hue, sat, 210]]], np.uint8), cv2.COLOR_HSV2BGR)[0, 0]
    img = synth.background(320, 240)
    cv2.circle(img, (160, 120), 20, tuple(int(v) for v in bgr), -1, lineType=cv2.LINE_AA)
    d = HsvBlobDetector(HsvConfig()).detect(img)
    assert lo <= d.confidence <= hi, d


def test_hsv_both_hue_ranges_are_needed() -> None:
    """A red at hue ~2 and one at hue ~176: each is found only through its own range."""
    bg = synth.background(320, 240)
    low_red = bg.copy()
    cv2.circle(low_red, (100, 100), 15, (10, 20, 220), -1)  # hue near 2
    high_red = bg.copy()
    cv2.circle(high_red, (100, 100), 15, (40, 15, 220), -1)  # hue near 176
    hsv_low = cv2.cvtColor(low_red, cv2.COLOR_BGR2HSV)[100, 100]
    hsv_high = cv2.cvtColor(high_red, cv2.COLOR_BGR2HSV)[100, 100]
    assert hsv_low[0] < 10 and hsv_high[0] > 170
    cfg = HsvConfig()
    both = HsvBlobDetector(cfg)
    only_first = HsvBlobDetector(HsvConfig(ranges=cfg.ranges[:1]))
    only_second = HsvBlobDetector(HsvConfig(ranges=cfg.ranges[1:]))
    assert both.detect(low_red).found and both.detect(high_red).found
    assert only_first.detect(low_red).found and not only_first.detect(high_red).found
    assert only_second.detect(high_red).found and not only_second.detect(low_red).found



def test_hsv_red_ranges_with_their_own_bounds() -> None:
    """Two red ranges with different S bounds cannot be merged into one mask; each is mirrored with the frame
    (red in one piece at hue 120) and the ball is found, scored as pure red."""
    cfg = HsvConfig(ranges=(((0, 120, 70), (6, 255, 255)), ((174, 100, 70), (179, 255, 255))))
    det = HsvBlobDetector(cfg)
    assert not det.single_range
    for bgr in ((10, 20, 220), (40, 15, 220)):  # hue near 2, near 176
        img = synth.background(320, 240)
        cv2.circle(img, (150, 110), 20, bgr, -1, cv2.LINE_AA)
        d = det.detect(img)
        assert d.found and d.confidence >= 0.85 and abs(d.cx - 150) <= 1.5 and abs(d.cy - 110) <= 1.5, (bgr, d)

def test_detection_errors_normalised() -> None:
    det = HsvBlobDetector(HsvConfig())
    d = det.detect(synth.red_disc(synth.background(320, 240), 240, 60, 10))
    assert d.error_x == pytest.approx(0.5, abs=0.01)
    assert d.error_y == pytest.approx(-0.5, abs=0.01)
    assert d.relative_size == pytest.approx(20 / 320, abs=0.01)


@pytest.mark.parametrize("width,height", SIZES)
@pytest.mark.parametrize("gain,noise", [(1.0, 0.0), (0.6, 4.0), (1.2, 6.0)])
def test_aruco_position_and_size(width: int, height: int, gain: float, noise: float) -> None:
    det = ArucoMarkerDetector(ArucoConfig(dictionary="DICT_4X4_50", marker_id=7))
    bg = synth.background(width, height)
    checked = 0
    for fx, fy, side in itertools.product((0.25, 0.5, 0.75), (0.3, 0.7), (36, 60)):
        cx, cy = int(fx * width), int(fy * height)
        img = synth.degrade(
            synth.paste_marker(bg, synth.marker_image(cv2.aruco.DICT_4X4_50, 7, side), cx, cy), gain, noise, checked
        )
        d = det.detect(img)
        assert d.found, (cx, cy, side)
        # the marker occupies pixels [x0, x0 + side): its centre is half a pixel before x0 + side / 2
        assert abs(d.cx - (cx - 0.5)) <= 2.0 and abs(d.cy - (cy - 0.5)) <= 2.0, (d, cx, cy)
        assert abs(d.size - side) <= 3.0, (d.size, side)
        checked += 1
    assert checked == 12


def test_aruco_ignores_other_ids_and_distractors() -> None:
    det = ArucoMarkerDetector(ArucoConfig(dictionary="DICT_4X4_50", marker_id=7))
    bg = synth.background(320, 240)
    other = synth.paste_marker(bg, synth.marker_image(cv2.aruco.DICT_4X4_50, 3, 60), 160, 120)
    assert not det.detect(other).found
    assert ArucoMarkerDetector(ArucoConfig(marker_id=-1)).detect(other).found
    red_only = synth.red_disc(bg, 160, 120, 30)
    assert not det.detect(red_only).found


def test_one_inrange_on_the_mirrored_hue_equals_one_inrange_per_range() -> None:
    """Red's two ranges become one range at hue 120 when the BGR frame is converted as RGB: the same mask,
    but for pixels whose hue sits on a range boundary (rounding of the mirrored hue)."""
    cfg = HsvConfig()
    fast = HsvBlobDetector(cfg)
    assert fast.single_range
    rng = np.random.default_rng(5)
    kernel = cv2.getStructuringElement(cv2.MORPH_RECT, (3, 3))
    for _ in range(5):
        img = rng.integers(0, 256, (120, 160, 3), dtype=np.uint8)
        hsv = cv2.cvtColor(img, cv2.COLOR_BGR2HSV)
        reference = np.zeros(hsv.shape[:2], np.uint8)
        for lo, hi in cfg.ranges:
            reference |= cv2.inRange(hsv, np.array(lo, np.uint8), np.array(hi, np.uint8))
        reference = cv2.morphologyEx(cv2.morphologyEx(reference, cv2.MORPH_OPEN, kernel), cv2.MORPH_CLOSE, kernel)
        differ = fast.mask(img) != reference
        assert np.count_nonzero(differ) <= 0.01 * differ.size
    general = HsvBlobDetector(HsvConfig(ranges=(((0, 120, 70), (8, 255, 255)), ((172, 100, 70), (179, 255, 255)))))
    assert not general.single_range  # different S bounds: one inRange per range


def test_the_aim_point_must_show_the_ball_not_what_is_in_front_of_it() -> None:
    det = HsvBlobDetector()
    frame = synth.red_disc(synth.background(320, 240), 160, 120, 25)
    assert det.aim_on_target(frame, 50.0)
    edge = frame.copy()
    cv2.circle(edge, (160 - 60, 120), 40, (200, 80, 20), -1)  # a blue ball over the left of the rim only
    assert det.detect(edge).found and det.aim_on_target(edge, 50.0)
    front = frame.copy()
    cv2.circle(front, (160 - 35, 120), 40, (200, 80, 20), -1)  # ... over the middle: the rim still fits a circle
    assert not det.aim_on_target(front, 50.0)
    assert not det.aim_on_target(synth.background(320, 240), 50.0)
    assert ArucoMarkerDetector().aim_on_target(frame, 50.0) is None  # cannot tell: never blocks on its own
