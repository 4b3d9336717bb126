"""ArUco with one corner covered (pilot/vision/aruco_corner.py): the marker is read from the rest of its square, no
other marker or empty view is taken for it, and the look runs only while the frame's budget lasts."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
import vision_imagery as vi

from pilot.common.config import ArucoConfig, VisionConfig
from pilot.vision.aruco import CORNER_SCORE, ArucoMarkerDetector
from pilot.vision.aruco_corner import cut_corner_quads


def covered(marker_id: int, cover: float, seed: int) -> tuple[np.ndarray, float, float]:
    """A 70 px marker on a grey wall with one corner covered by a box of grey ``cover``; and its centre."""
    rng = np.random.default_rng(seed)
    img = np.full((240, 320, 3), 150, np.uint8)
    cx, cy = 160.0 + rng.uniform(-40, 40), 120.0 + rng.uniform(-30, 30)
    saved = vi.MARKER_ID
    vi.MARKER_ID = marker_id
    try:
        corners = vi.marker(img, cx, cy, 70.0, rng)
    finally:
        vi.MARKER_ID = saved
    k = seed % 4
    c, a, b = corners[k], corners[(k + 1) % 4], corners[(k - 1) % 4]
    t = math.sqrt(vi.CORNER_SHARE)
    box = np.array([c - (a - c) * t - (b - c) * t, c + (a - c) * t - (b - c) * t, c + (a - c) * t + (b - c) * t,
                    c - (a - c) * t + (b - c) * t])
    cv2.fillConvexPoly(img, np.round(box).astype(np.int32), (cover, cover, cover))
    centre = corners.mean(axis=0)  # the black square's, which the slight obliquity moves off (cx, cy)
    return img, float(centre[0]), float(centre[1])


@pytest.mark.parametrize("cover,seed", [(40, 0), (90, 2), (200, 1), (200, 5), (60, 3), (60, 4)])
def test_a_marker_with_a_covered_corner_is_read(cover: int, seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    img, cx, cy = covered(7, cover, seed)
    found = ArucoMarkerDetector(ArucoConfig(marker_id=7)).candidates(img)
    assert found and found[0].score == CORNER_SCORE
    assert math.hypot(found[0].cx - cx, found[0].cy - cy) < 4.0
    monkeypatch.setattr("pilot.vision.aruco.corner_covered_markers", lambda *a, **k: [])
    assert ArucoMarkerDetector(ArucoConfig(marker_id=7)).candidates(img) == []  # OpenCV alone misses it


@pytest.mark.parametrize("other", [3, 8, 21])
def test_another_marker_with_a_covered_corner_is_not_taken_for_it(other: int) -> None:
    for seed in range(4):
        img, _, _ = covered(other, 60, seed)
        assert ArucoMarkerDetector(ArucoConfig(marker_id=7)).candidates(img) == []


def test_empty_photo_views_give_no_covered_marker() -> None:
    rng = np.random.default_rng(17)
    det = ArucoMarkerDetector()
    assert sum(bool(det.candidates(vi.empty_sample(rng, vi.TUNING).image)) for _ in range(60)) == 0


def test_the_covered_corner_look_stops_at_the_budget() -> None:
    img, _, _ = covered(7, 60, 0)
    t = [0.0]

    def clock() -> float:
        t[0] += 0.004  # 4 ms a read: the budget of 2 ms is spent before the look
        return t[0]

    det = ArucoMarkerDetector(ArucoConfig(marker_id=7), VisionConfig(budget_ms=2.0), clock=clock)
    assert det.candidates(img) == [] and det.cut_short


def test_a_pentagon_gives_back_its_cut_corner() -> None:
    square = np.array([[0, 0], [100, 0], [100, 100], [0, 100]], np.float64)
    cut = np.array([[30, 0], [100, 0], [100, 100], [0, 100], [0, 30]], np.float64)  # the corner at (0, 0) cut
    quads = cut_corner_quads(cut)
    assert any(np.allclose(np.sort(q, axis=0), np.sort(square, axis=0)) for q in quads)


def test_a_tracked_marker_whose_corner_gets_covered_stays_tracked_whatever_the_budget() -> None:
    from pilot.vision.detect import TrackedDetector

    img, cx, cy = covered(7, 60, 3)
    whole = img.copy()
    clean_img = np.full((240, 320, 3), 150, np.uint8)
    rng = np.random.default_rng(3)
    centre = vi.marker(clean_img, 160.0 + rng.uniform(-40, 40), 120.0 + rng.uniform(-30, 30), 70.0, rng).mean(axis=0)
    assert abs(centre[0] - cx) < 1e-6 and abs(centre[1] - cy) < 1e-6  # the same marker, uncovered
    t = [0.0]

    def clock() -> float:
        t[0] += 0.004  # every frame's budget (2 ms) is spent before the frame's own covered-corner look
        return t[0]

    source = ArucoMarkerDetector(ArucoConfig(marker_id=7), VisionConfig(budget_ms=2.0), clock=clock)
    det = TrackedDetector(source, 0.3, 60.0, VisionConfig(budget_ms=2.0))
    for _ in range(3):
        assert det.detect(clean_img + np.uint8(_)).found  # tracked on the whole marker (frames differ: not frozen)
    covered_now = det.detect(whole)
    assert covered_now.found and not covered_now.predicted and covered_now.confidence == CORNER_SCORE
    assert math.hypot(covered_now.cx - cx, covered_now.cy - cy) < 4.0


def test_a_covered_marker_must_read_every_uncovered_cell() -> None:
    """One code cell read otherwise let 13 of the 4,096 codes of the 12 uncovered bits match: an empty view of the
    tuning sources read as a marker."""
    from pilot.vision.aruco_corner import COVERED, matches, reference_cells

    refs = reference_cells(cv2.aruco.getPredefinedDictionary(vi.MARKER_DICT), vi.MARKER_ID)
    cells = refs[0].copy()
    cells[:COVERED, :COVERED] = ~cells[:COVERED, :COVERED]  # the covered corner: read as anything
    assert matches(cells, refs)
    cells[COVERED + 1, COVERED] = ~cells[COVERED + 1, COVERED]  # one uncovered code cell read otherwise
    assert not any(matches(np.rot90(cells, k), refs) for k in range(4))
