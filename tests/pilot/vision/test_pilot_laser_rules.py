"""The laser's steadiness rule (pilot/vision/gating.py): the gate confirms a streak of one steady thing, frame to
frame its size within ``STEADY_SIZE`` and its centre within ``STEADY_STEP`` of its size; a hop or a jump in size
starts the streak again at the new thing."""

from __future__ import annotations

from pilot.common.config import ControllerConfig
from pilot.vision.detection import Detection
from pilot.vision.gating import STEADY_SIZE, STEADY_STEP, Gate


def good(cx: float = 160.0, size: float = 60.0) -> Detection:
    """A confident, centred, near target's measured detection."""
    return Detection(True, cx, 120.0, size, 0.9, 320, 240, range_m=1.4)


def confirms(frames: list[Detection], steadiness: bool = True) -> bool:
    gate = Gate(ControllerConfig(), steadiness)
    for d in frames:
        gate.observe(d)
    return gate.confirmed()


def test_a_steady_target_within_the_steps_allowed_confirms() -> None:
    n = ControllerConfig().confirm_frames
    drift = [good(cx=150 + 0.9 * STEADY_STEP * 30 * k, size=30 * (0.97 * STEADY_SIZE) ** (k % 2)) for k in range(n)]
    assert confirms(drift)


def test_a_hop_or_a_jump_in_size_starts_the_streak_again() -> None:
    n = ControllerConfig().confirm_frames
    hop = [good(size=30)] * (n - 1) + [good(size=30, cx=160 + 1.1 * STEADY_STEP * 30)]
    grow = [good()] * (n - 1) + [good(size=60 * 1.05 * STEADY_SIZE)]
    shrink = [good()] * (n - 1) + [good(size=60 / (1.05 * STEADY_SIZE))]
    for frames in (hop, grow, shrink):
        assert not confirms(frames) and confirms(frames, steadiness=False)
        assert not confirms(frames + [frames[-1]] * (n - 2))
        assert confirms(frames + [frames[-1]] * (n - 1))  # the new thing's own streak starts at it


def test_a_frame_that_breaks_the_streak_leaves_no_steadiness_behind() -> None:
    """After a miss, the next frame starts a streak whatever the last one measured."""
    n = ControllerConfig().confirm_frames
    miss = Detection(False, width=320, height=240)
    assert confirms([good(size=30)] + [miss] + [good(size=60)] * n)
