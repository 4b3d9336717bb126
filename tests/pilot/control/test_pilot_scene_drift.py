"""The drift read from the whole scene's motion: learnt where the target gives no speed (a search, a loss), the
commanded turn taken out, the forward speed only once the pilot's own pitch is old."""

from __future__ import annotations

import math

import drone_protocol as dp
import pytest

from pilot.control.pulses import StickModel
from pilot.control.scene_drift import DEPTH_M, GAIN, scene_speeds
from pilot.control.trim import FRAME_AGE_S, SCENE_CALM_MS, DriftHold
from pilot.vision.detection import SceneShift

PULSES = StickModel()
DT = 0.05


def shift(right_mps: float = 0.0, forward_mps: float = 0.0, turned_deg: float = 0.0) -> SceneShift:
    """What one frame's scene shows of a drone moving so (at the room's typical depth) and turning so."""
    return SceneShift(turned_deg + math.degrees(right_mps * DT / DEPTH_M), 1.0 + forward_mps * DT / DEPTH_M, 40)


def test_the_scene_reads_as_speeds_less_the_commanded_turn() -> None:
    right, forward = scene_speeds(shift(0.3, -0.4, 1.0), 1.0, DT) or (0.0, 0.0)
    assert right == pytest.approx(0.3 * GAIN, abs=1e-6) and forward == pytest.approx(-0.4 * GAIN, abs=1e-6)
    assert scene_speeds(shift(0.0, 0.0, 1.0), 1.0, DT) == pytest.approx((0.0, 0.0))
    assert scene_speeds(None, 0.0, DT) is None
    assert scene_speeds(SceneShift(20.0, 1.0, 40), 0.0, DT) == pytest.approx((GAIN, 0.0))  # a wild fit: bounded


def _unseen(hold: DriftHold, seconds: float, frame: bytes, scene: SceneShift | None, t0: int = 0) -> int:
    t = t0
    for _ in range(round(seconds / DT)):
        hold.step(frame, t, None, None, True, scene)
        t += round(DT * 1000)
    return t


def test_a_drone_drifting_back_unseen_learns_to_lean_forward_only_from_the_scene() -> None:
    blind = DriftHold(PULSES, 5.0)
    _unseen(blind, 3.0, dp.hold_altitude(), None)
    assert blind.drift.forward == 0.0 and blind.drift.right == 0.0  # the target alone: nothing to learn from
    hold = DriftHold(PULSES, 5.0)
    _unseen(hold, 3.0, dp.hold_altitude(), shift(right_mps=-0.3, forward_mps=-0.4))
    # lean forward and right against it, at the scene's share of the learning rate (1°/s per m/s)
    assert hold.drift.forward == pytest.approx(0.4 * 3.0 * GAIN, rel=0.1)
    assert hold.drift.right == pytest.approx(0.3 * 3.0 * GAIN, rel=0.1)


def test_the_pilots_own_pitch_is_no_drift_until_it_is_old() -> None:
    back = dp.move_backward(dp.CHANNELS[dp.ChannelName.PITCH].median - 200)
    hold = DriftHold(PULSES, 5.0)
    t = _unseen(hold, 1.0, back, shift(forward_mps=-0.4))
    t = _unseen(hold, SCENE_CALM_MS / 1000.0 - 0.1, dp.hold_altitude(), shift(forward_mps=-0.4), t)
    assert hold.drift.forward == 0.0  # braked within the calm time: the scene's motion is the brake's
    _unseen(hold, 1.0, dp.hold_altitude(), shift(forward_mps=-0.4), t)
    assert hold.drift.forward > 0.4 * 0.5 * GAIN


def test_a_gentle_turn_is_taken_out_and_only_a_slide_is_learnt() -> None:
    """The scene turns with the body, shown ``FRAME_AGE_S`` late as the frames are: a turn alone teaches nothing."""
    unit = PULSES.unit_us(dp.ChannelName.YAW, True) / 4.0
    rate = PULSES.turn_dps(unit)
    turn = dp.turn_right(round(dp.CHANNELS[dp.ChannelName.YAW].median + unit))
    lag = round(FRAME_AGE_S / DT)

    def fly(slide: float) -> float:
        hold = DriftHold(PULSES, 5.0)
        heading = [0.0]
        for k in range(60):
            turning = k % 20 < 8
            shown = heading[max(0, k - lag)] - heading[max(0, k - 1 - lag)]
            hold.step(turn if turning else dp.hold_altitude(), 50 * k, None, None, True, shift(slide, 0.0, shown))
            heading.append(heading[-1] + (rate * DT if turning else 0.0))
        return hold.drift.right

    assert abs(fly(0.0)) < 0.02
    assert fly(0.3) < -0.3 * 2.0 * GAIN
