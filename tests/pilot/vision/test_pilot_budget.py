"""The per-frame budget (``vision.budget_ms``): a frame full of the target's colour stops refining when the time is
spent, keeps the best candidate found so far, says so (the Detection and the log), and never costs the tick."""

from __future__ import annotations

import logging
import time

import cv2
import numpy as np
import pytest

import pilot.vision.budget as budget_mod
from pilot.common.config import PilotConfig, VisionConfig, validate
from pilot.common.errors import ConfigError
from pilot.vision.budget import FrameBudget
from pilot.vision.detect import TrackedDetector
from pilot.vision.hsv.detector import HsvBlobDetector

RED = (30, 20, 200)


class StepClock:
    """A clock that moves ``step_ms`` each time it is read: the more the detector does, the more time passes."""

    def __init__(self, step_ms: float) -> None:
        self.t, self.step, self.reads = 0.0, step_ms / 1e3, 0

    def __call__(self) -> float:
        self.reads += 1
        self.t += self.step
        return self.t


def red_heavy() -> np.ndarray:
    """A grey room scattered with red patches and slabs (each a blob to refine or split), and one red ball, the
    largest round blob."""
    rng = np.random.default_rng(3)
    img = np.full((240, 320, 3), 110, np.uint8)
    for _ in range(40):
        x, y = int(rng.integers(0, 300)), int(rng.integers(0, 220))
        cv2.rectangle(img, (x, y), (x + int(rng.integers(6, 30)), y + int(rng.integers(4, 12))), RED, -1)
    cv2.circle(img, (250, 160), 28, (90, 90, 90), -1)  # clear the ball's surroundings
    cv2.circle(img, (250, 160), 18, RED, -1)
    return img


def test_a_spent_budget_keeps_the_best_candidate_and_says_so(caplog: pytest.LogCaptureFixture) -> None:
    img = red_heavy()
    free = HsvBlobDetector()  # time never passes (conftest.py): every look runs
    found = free.candidates(img)
    assert not free.cut_short and found
    clock = StepClock(1.0)
    det = HsvBlobDetector(vision=VisionConfig(budget_ms=2.0), clock=clock)
    with caplog.at_level(logging.INFO, logger="pilot.vision.hsv.detector"):
        cut = det.candidates(img)
    assert det.cut_short
    assert clock.reads < 20  # a handful of checks, not the whole look
    assert cut and abs(cut[0].cx - 250) < 2 and abs(cut[0].cy - 160) < 2  # the largest blob: the ball
    assert any("budget of 2.0 ms spent" in r.getMessage() for r in caplog.records)


def test_the_budget_starts_again_each_frame() -> None:
    img = red_heavy()
    clock = StepClock(0.0)
    det = HsvBlobDetector(vision=VisionConfig(budget_ms=2.0), clock=clock)
    clock.step = 1e-3
    det.candidates(img)
    assert det.cut_short
    clock.step = 0.0
    det.candidates(img)
    assert not det.cut_short


def test_the_tracked_detection_reports_a_cut_short_frame() -> None:
    img = red_heavy()
    source = HsvBlobDetector(vision=VisionConfig(budget_ms=2.0), clock=StepClock(1.0))
    d = TrackedDetector(source, 0.3, 60.0, VisionConfig(budget_ms=2.0)).detect(img)
    assert d.found and d.cut_short


def test_frame_budget_is_sticky_until_the_next_frame() -> None:
    clock = StepClock(0.0)
    b = FrameBudget(5.0, clock)
    b.start()
    assert not b.out()
    clock.t += 0.006
    assert b.out() and b.exhausted
    clock.t -= 0.006  # a clock read earlier cannot give the time back
    assert b.out()
    b.start()
    assert not b.out()


@pytest.mark.parametrize("value", [0.0, -1.0, 51.0])
def test_a_budget_past_the_tick_or_not_positive_is_refused_by_name(value: float) -> None:
    cfg = PilotConfig(vision=VisionConfig(budget_ms=value))
    with pytest.raises(ConfigError, match=r"vision\.budget_ms"):
        validate(cfg, "pilot.yaml")


def test_a_budget_given_no_clock_reads_the_module_clock(monkeypatch: pytest.MonkeyPatch) -> None:
    clock = StepClock(1.0)
    monkeypatch.setattr(budget_mod, "CLOCK", clock)
    det = HsvBlobDetector(vision=VisionConfig(budget_ms=2.0))
    det.candidates(red_heavy())
    assert det.cut_short and clock.reads > 0


def test_the_default_clock_counts_the_threads_cpu_not_the_wait(monkeypatch: pytest.MonkeyPatch) -> None:
    """Another process's turns on a shared core must not cut a frame short: the budget counts this thread's CPU
    time. A 20 ms sleep (no CPU) leaves a 5 ms budget unspent, where the wall clock would have spent it."""
    monkeypatch.undo()  # conftest.py froze the module clock: the real default here
    b = FrameBudget(5.0)
    b.start()
    time.sleep(0.02)
    assert not b.out()
    t0 = time.thread_time()
    while time.thread_time() - t0 < 0.006:  # 6 ms of this thread's own work
        pass
    assert b.out()


def test_make_detector_passes_its_clock_to_either_detector() -> None:
    from pilot.vision.aruco import ArucoMarkerDetector
    from pilot.vision.detect import make_detector
    from pilot.vision.verify import VerifiedSource

    clock = StepClock(0.0)
    verified = make_detector(PilotConfig(), clock=clock).source
    aruco = make_detector(PilotConfig(detector="aruco"), clock=clock).source
    assert isinstance(verified, VerifiedSource)  # the colour-ball detector behind its learned verifier
    hsv = verified.source
    assert isinstance(hsv, HsvBlobDetector) and hsv.budget.clock is clock
    assert isinstance(aruco, ArucoMarkerDetector) and aruco.budget.clock is clock


def test_the_circle_look_stops_inside_a_window_when_the_budget_is_spent() -> None:
    """A red-heavy window's circle look took up to 12 ms past the budget when the budget was asked only before it:
    it is asked before each vote and each circle's rim."""
    from pilot_synth import on_surface

    from pilot.vision.hsv.circles import circles

    img = on_surface(12, 0, 40)
    mask, roi = HsvBlobDetector().mask(img), cv2.medianBlur(img, 3)
    assert circles(roi, mask, img, 0, 0)  # time left: the ball's circle
    asked: list[int] = []

    def spent() -> bool:
        asked.append(1)
        return False

    assert circles(roi, mask, img, 0, 0, spent) == [] and len(asked) == 2  # no colour vote, no rim read


def test_the_edge_cut_measures_no_piece_once_the_budget_is_spent(monkeypatch: pytest.MonkeyPatch) -> None:
    import pilot.vision.hsv.edges as edges
    import pilot.vision.hsv.refine as refine

    det = HsvBlobDetector(vision=VisionConfig(budget_ms=2.0), clock=lambda: 0.0)
    real, cuts, measured = edges.cut_by_edges, [], []

    def cut_then_spent(*args: object, **kw: object) -> object:
        out = real(*args, **kw)  # type: ignore[arg-type]
        cuts.append(len(out.pieces))
        det.budget.exhausted = True  # the time ran out while the window was cut
        return out

    monkeypatch.setattr(refine, "cut_by_edges", cut_then_spent)
    img = red_heavy()
    cv2.rectangle(img, (20, 20), (140, 120), RED, -1)  # a red slab with a ball on it: cut by the edges
    cv2.circle(img, (80, 70), 20, (20, 10, 120), -1)
    monkeypatch.setattr(det, "measure", lambda *a, **k: measured.append(1))  # the pieces' measure
    det._edge_split(img, det.colour.bounds_for(img), [(1.0, np.zeros((1, 1, 2), np.int32), (8, 8, 70, 60))], 2, [])
    assert cuts and cuts[0] > 0 and not measured
