"""The vision pipeline's guarantees: typed bad-frame results, the gate, and a small real-photo evaluation
(tuning photos only; the full one with the held-out photos is ``make bench-vision``)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import vision_eval as ve
import vision_imagery as vi

from pilot.common.config import ControllerConfig, PilotConfig
from pilot.common.errors import ConfigError
from pilot.control.controller import Controller, State
from pilot.vision.aruco import ArucoMarkerDetector
from pilot.vision.detect import make_detector
from pilot.vision.detection import Candidate, Detection, FrameStatus
from pilot.vision.gating import Gate
from pilot.vision.hsv.detector import HsvBlobDetector


@pytest.mark.parametrize(
    "image,status",
    [
        (np.zeros((240, 320, 3), np.uint8), FrameStatus.BLACK),
        (np.full((240, 320, 3), 255, np.uint8), FrameStatus.SATURATED),
        (np.zeros((240, 320), np.uint8) + 100, FrameStatus.WRONG_SHAPE),
        (np.zeros((240, 320, 4), np.uint8) + 100, FrameStatus.WRONG_SHAPE),
        (np.zeros((240, 320, 3), np.float32) + 100, FrameStatus.WRONG_TYPE),
        ("not an image", FrameStatus.WRONG_TYPE),
    ],
)
def test_bad_frames_are_named_and_never_found(image: object, status: FrameStatus) -> None:
    det = make_detector(PilotConfig()).detect(image)  # type: ignore[arg-type]
    assert det.status is status and not det.found


MALFORMED = [
    (np.zeros((240, 320), np.uint8) + 100, FrameStatus.WRONG_SHAPE),
    (np.zeros((240, 320, 4), np.uint8) + 100, FrameStatus.WRONG_SHAPE),
    (np.zeros((8, 8, 3), np.uint8) + 100, FrameStatus.WRONG_SHAPE),
    (np.zeros((1, 640, 3), np.uint8) + 100, FrameStatus.WRONG_SHAPE),  # wide enough for the half-size search
    (np.zeros((0, 0, 3), np.uint8), FrameStatus.WRONG_SHAPE),
    (np.zeros((240, 320, 3), np.float32) + 100, FrameStatus.WRONG_TYPE),
    (None, FrameStatus.WRONG_TYPE),
]


@pytest.mark.parametrize("image,status", MALFORMED)
def test_single_frame_detectors_name_malformed_frames(image: object, status: FrameStatus) -> None:
    """The single-frame ``detect`` (no tracking) answers a malformed frame with its status, not an OpenCV error."""
    for det in (HsvBlobDetector(), ArucoMarkerDetector()):
        out = det.detect(image)  # type: ignore[arg-type]
        assert out.status is status and not out.found, det.name


@pytest.mark.parametrize("image,status", MALFORMED)
def test_candidate_sources_find_nothing_in_malformed_frames(image: object, status: FrameStatus) -> None:
    """The lower-level calls a caller may make without ``detect``: no candidate and no OpenCV error (a 1-pixel-tall
    frame 640 wide once reached the half-size search and failed in its resize); the aim point does not hold."""
    for det in (HsvBlobDetector(), ArucoMarkerDetector()):
        assert det.candidates(image) == [], (det.name, status)  # type: ignore[arg-type]
        assert det.candidates_near(image, 4.0, 4.0, 6.0) == [], det.name  # type: ignore[arg-type]
        assert not det.aim_on_target(image, 6.0), det.name  # type: ignore[arg-type]


def test_frozen_camera_and_size_change() -> None:
    det = make_detector(PilotConfig())
    rng = np.random.default_rng(0)
    frame = vi.target_sample(rng, vi.TUNING, "clean", "ball", (40, 60)).image
    results = [det.detect(frame).status for _ in range(6)]
    assert results[:4] == [FrameStatus.OK] * 4 and results[4:] == [FrameStatus.FROZEN] * 2
    assert det.detect(np.ascontiguousarray(frame[:200, :300])).status is FrameStatus.WRONG_SHAPE


def state_of(c: Controller) -> State:
    return c.state


def _flying_controller(cfg: ControllerConfig) -> Controller:
    c = Controller(cfg, clock=lambda: 0.0)
    c.state = State.SEARCH
    return c


def test_gate_low_confidence_is_no_sighting_and_bad_frames_hold_then_land() -> None:
    cfg = ControllerConfig()
    c = _flying_controller(cfg)
    weak = Detection(True, 160, 120, 40, cfg.acquire_confidence - 0.01, 320, 240, range_m=2.0)
    c.update(weak)
    assert state_of(c) is State.SEARCH and not c.gate.acquired()
    strong = dataclasses.replace(weak, confidence=cfg.acquire_confidence)
    c.update(strong)
    assert state_of(c) is State.ACQUIRE
    black = Detection(False, width=320, height=240, status=FrameStatus.BLACK)
    for _ in range(cfg.blind_frames - 1):
        assert c.update(black) is not None and state_of(c) is State.ACQUIRE  # hold (hold_altitude)
    c.update(black)
    assert state_of(c) is State.LAND


def test_gate_confirms_only_measured_centred_near_frames_in_a_row() -> None:
    cfg = ControllerConfig()
    gate = Gate(cfg)
    good = Detection(True, 160, 120, 60, 0.9, 320, 240, range_m=1.4)
    for bad in (dataclasses.replace(good, predicted=True), dataclasses.replace(good, cx=200),
                dataclasses.replace(good, range_m=cfg.fire_range_max_m + 1), dataclasses.replace(good, confidence=0.1)):
        for _ in range(cfg.confirm_frames - 1):
            gate.observe(good)
        gate.observe(bad)
        assert not gate.confirmed()
    for _ in range(cfg.confirm_frames):
        gate.observe(good)
    assert gate.confirmed()


@pytest.mark.parametrize(
    "option,value", [("acquire_confidence", 1.5), ("confirm_frames", 0), ("fire_range_max_m", 99.0)]
)
def test_gate_options_out_of_range_are_refused_by_name(option: str, value: float) -> None:
    with pytest.raises(ConfigError, match=f"controller.{option}"):
        from pilot.common.config import from_dict

        from_dict({"controller": {option: value}})


@pytest.fixture(scope="module")
def small_eval() -> tuple[list[ve.Record], list[ve.Record]]:
    ball = ve.samples(vi.TUNING, 11, 12, 60, 8, "ball", (16.0, 120.0), vi.CONDITIONS)
    markers = ve.samples(vi.TUNING, 12, 12, 0, 0, "marker", (24.0, 120.0), ("clean", "motion_blur"))
    negatives = [s for s in ball if s.kind != "target"]
    return ve.run(HsvBlobDetector().candidates, ball), ve.run(ArucoMarkerDetector().candidates, markers + negatives)


def _scripted(cands: list[Candidate]) -> ve.Candidates:
    """A detector returning a fixed list of candidates, whatever the frame."""
    return lambda image: cands


def test_evaluation_tells_a_miss_of_the_score_from_a_miss_of_the_candidates() -> None:
    """A target view whose best candidate is elsewhere is a miss; it still counts as reached when a lower
    candidate lies at the ball, and not when none does. Views without a target are never reached."""
    img = np.zeros((240, 320, 3), np.uint8)
    ball = vi.Sample(img, "target", "clean", 40.0, 100.0, 80.0, "coffee")
    wrong, right = Candidate(250.0, 200.0, 40.0, 0.9), Candidate(104.0, 83.0, 38.0, 0.4)
    (second,) = ve.run(_scripted([wrong, right]), [ball])
    assert second.found and second.confidence == 0.9 and not ve.correct(second, 0.6) and second.reached
    (none,) = ve.run(_scripted([wrong]), [ball])
    assert none.found and not none.reached
    (best,) = ve.run(_scripted([right]), [ball])
    assert ve.correct(best, 0.3) and best.reached and best.error == pytest.approx(5.0)
    (empty,) = ve.run(_scripted([right]), [vi.Sample(img, "empty", "clean")])
    assert empty.found and not empty.reached
    rows = ve.target_rows([second, none], 0.6, 16)
    assert rows[0].rate == 0.0 and rows[0].reached == 0.5


def test_real_photos_aruco_never_lights_a_non_marker_and_reads_clean_markers(
    small_eval: tuple[list[ve.Record], list[ve.Record]],
) -> None:
    _, aruco = small_eval
    rows = {r.group: r.rate for r in ve.target_rows(aruco, 0.5, 0)}
    assert rows["clean"] >= 0.9  # goal: >= 90 %
    assert ve.false_rows(aruco, 0.5, "empty")[-1].rate == 0.0  # goal: 0 false positives
    assert ve.false_rows(aruco, 0.5, "distractor")[-1].rate == 0.0


def test_real_photos_aruco_reads_markers_through_motion_blur() -> None:
    """A regression floor on 200 markers under motion blur (tuning photos; a seed of its own): 88 % are read with
    each cell read from 8x8 pixels of the unwarped marker, 82 % with OpenCV's 4x4 (goal: >= 80 %)."""
    markers = ve.samples(vi.TUNING, 22, 200, 0, 0, "marker", (24.0, 120.0), ("motion_blur",))
    rows = {r.group: r.rate for r in ve.target_rows(ve.run(ArucoMarkerDetector().candidates, markers), 0.5, 0)}
    assert rows["motion_blur"] >= 0.86


def test_real_photos_hsv_floors(small_eval: tuple[list[ve.Record], list[ve.Record]]) -> None:
    """Regression floors at the levels reached (bench/vision/RESULTS.md); the issue's goals (recall >= 90 %,
    empty <= 1 %, distractors <= 2 %) are not all met yet, and this test does not pretend they are."""
    hsv, _ = small_eval
    threshold = ControllerConfig().acquire_confidence
    target_rows = ve.target_rows(hsv, threshold, 16)
    assert all(r.reached >= r.rate for r in target_rows)  # a correct detection is a candidate at the ball
    rows = {r.group: r.rate for r in target_rows}
    assert sum(rows.values()) / len(rows) >= 0.75  # 0.84 reached (0.78 before the split and the ellipse)
    assert ve.false_rows(hsv, threshold, "empty")[-1].rate <= 0.02  # at most 1 of 60 (none now)
    assert ve.false_rows(hsv, threshold, "distractor")[-1].rate <= 0.05  # at most 2 of 40 (none now)
    # the recall by photo covers the same views, every condition but occlusion
    by_photo = ve.photo_rows(hsv, threshold, 16)
    counted = [r for r in hsv if r.kind == "target" and r.group != "occlusion" and r.size >= 16]
    assert {r.group for r in by_photo} == {r.photo for r in counted} and set(vi.TUNING) >= {r.group for r in by_photo}
    assert sum(r.n for r in by_photo) == len(counted)
    assert sum(round(r.rate * r.n) for r in by_photo) == sum(ve.correct(r, threshold) for r in counted)


def test_real_photos_hsv_stays_quiet_in_red_and_orange_scenes() -> None:
    """scikit-learn's two photos (a temple's red columns, a dahlia close up) are the target's colour throughout:
    empty views there fire the detector far more often than elsewhere. A regression floor: 6 of these 300 fire
    now, 12 did before the circle look's checks for hollows and textures (pilot/vision/hsv/circles.py)."""
    views = ve.samples(vi.VALIDATION, 15, 0, 300, 0, "ball", (16.0, 120.0), ())
    empty = ve.false_rows(ve.run(HsvBlobDetector().candidates, views), ControllerConfig().acquire_confidence, "empty")
    assert empty[-1].group == "all" and empty[-1].n == 300
    assert empty[-1].rate <= 9 / 300
