"""The drift: its trim learnt from the target's sideways and closing speeds, and leant against with the roll and
pitch sticks in the frames the controller leaves free; the lead the recent pitch commands add to the closing
speed."""

from __future__ import annotations

import dataclasses
import math

import drone_protocol as dp
import pytest
from controller_rig import CFG, name, seen, size_at, to_state

from pilot.control.approach import Lead
from pilot.control.controller import State
from pilot.control.pulses import StickModel
from pilot.control.trim import DEBT_MAX_DEG_S, FRAME_AGE_S, LATERAL_WINDOW_S, Drift, DriftHold, TrimSticks

PULSES = StickModel()
ROLL, PITCH = dp.ChannelName.ROLL, dp.ChannelName.PITCH


def lean_of(frame: bytes | None) -> tuple[float, float]:
    """The (right, forward) lean a frame asks for, degrees."""
    assert frame is not None
    c = dp.decode(frame)
    senses = {dp.CommandName.MOVE_RIGHT: (ROLL, 1.0), dp.CommandName.MOVE_LEFT: (ROLL, -1.0),
              dp.CommandName.MOVE_FORWARD: (PITCH, 1.0), dp.CommandName.MOVE_BACKWARD: (PITCH, -1.0)}
    if c.name not in senses:
        return 0.0, 0.0
    channel, sense = senses[c.name]
    deg = sense * PULSES.lean_deg(c.value - dp.CHANNELS[channel].median, channel)
    return (deg, 0.0) if channel is ROLL else (0.0, deg)


def test_a_lean_pulse_clears_the_dead_zone_and_reads_back_as_the_lean() -> None:
    for channel in (ROLL, PITCH):
        assert PULSES.lean_offset_us(channel, 0.0) == 0
        for deg in (0.3, 0.6, 5.0, -0.6):
            offset = PULSES.lean_offset_us(channel, deg)
            assert math.copysign(1, offset) == math.copysign(1, deg)
            assert PULSES.lean_deg(offset, channel) == pytest.approx(abs(deg), abs=0.04)  # 1 µs is 0.0625°


def test_the_sideways_speed_is_the_slope_of_the_lateral_offset() -> None:
    d = Drift()
    assert d.sideways is None
    for k in range(10):  # the target 3 m ahead, its lateral offset shrinking 0.2 m/s: the drone moves right
        t = k * 0.05
        d.see(t, 3.0, math.degrees(math.asin((0.5 - 0.2 * t) / 3.0)))
    assert d.sideways == pytest.approx(0.2, abs=1e-6)
    d.heading_moved()
    assert d.sideways is None


def test_the_trim_learns_against_the_drift_and_is_bounded() -> None:
    d = Drift(max_deg=1.0)
    d.learn(0.3, -0.2, 1.0)  # drifting right and backwards: lean left and forward
    assert d.right < 0.0 and d.forward > 0.0
    for _ in range(100):
        d.learn(0.5, None, 1.0)
    assert d.right == -1.0 and d.forward > 0.0


def test_holds_carry_the_trim_so_that_its_average_is_the_wanted_lean() -> None:
    sticks = TrimSticks(PULSES, 5.0)
    right, forward, total = -0.6, 0.3, [0.0, 0.0]
    for k in range(200):  # 10 s of holds at 20 Hz
        frame = sticks.shape(dp.hold_altitude(), 50 * k, right, forward, forward)
        r, f = lean_of(frame)
        total[0] += r * 0.05
        total[1] += f * 0.05
    assert total[0] / 10.0 == pytest.approx(right, abs=0.05)
    assert total[1] / 10.0 == pytest.approx(forward, abs=0.05)


def test_no_trim_leaves_the_hold_and_a_pitch_command_carries_the_pitch_trim() -> None:
    sticks = TrimSticks(PULSES, 5.0)
    assert sticks.shape(dp.hold_altitude(), 0, 0.0, 0.0, 0.0) == dp.hold_altitude()
    assert sticks.shape(dp.hold_altitude(), 50, 0.0, 0.0, 0.0) == dp.hold_altitude()
    forward = dp.move_forward(1600)
    _, plain = lean_of(forward)
    _, trimmed = lean_of(sticks.shape(forward, 100, 0.0, 0.5, 0.5))
    assert trimmed == pytest.approx(plain + 0.5, abs=0.07)
    turn = dp.turn_left(1424)
    assert sticks.shape(turn, 150, 1.0, 1.0, 1.0) == turn  # a turn is never replaced
    servo = dp.servo_up(3)
    assert sticks.shape(servo, 200, 1.0, 1.0, 1.0) == servo


def test_the_hold_learns_only_from_sightings_at_a_settled_heading_and_applies_only_when_asked() -> None:
    hold = DriftHold(PULSES, 5.0)
    t = 0
    for _ in range(40):  # 2 s: the target's lateral offset shrinks 0.3 m/s (the drone drifts right)
        lateral = 0.6 - 0.3 * t / 1000.0
        frame = hold.step(dp.hold_altitude(), t, (3.0, math.degrees(math.asin(lateral / 3.0))), None, True)
        t += 50
    assert hold.drift.right < 0.0  # learnt: lean left
    assert lean_of(frame)[0] < 0.0 or lean_of(frame)[1] != 0.0
    assert hold.step(dp.hold_altitude(), t, None, None, False) == dp.hold_altitude()


def _turning_past(hold: DriftHold, slide_mps: float) -> float:
    """Two seconds of a drone turning right at a quarter step for 0.4 s in every second, the target 3 m away at a
    fixed place, the drone sliding ``slide_mps`` to the right; each frame shows the heading ``FRAME_AGE_S`` ago."""
    rate = PULSES.turn_dps(PULSES.unit_us(dp.ChannelName.YAW, True) / 4.0)
    turn = dp.turn_right(round(dp.CHANNELS[dp.ChannelName.YAW].median + PULSES.unit_us(dp.ChannelName.YAW, True) / 4))
    heading: list[float] = [0.0]
    for k in range(40):
        t = 50 * k
        turning = k % 20 < 8
        shown = heading[max(0, k - round(FRAME_AGE_S / 0.05))]
        lateral = 0.2 - slide_mps * t / 1000.0  # across the line of sight at heading 0
        bearing = math.degrees(math.asin(lateral / 3.0)) - shown
        hold.step(turn if turning else dp.hold_altitude(), t, (3.0, bearing), None, False)
        heading.append(heading[-1] + (rate * 0.05 if turning else 0.0))
    return hold.drift.right


def test_a_turn_is_reckoned_so_that_only_a_sliding_drone_teaches_a_trim() -> None:
    """The target's bearing moves with the pilot's own turns: the reckoned heading takes them out, and only the
    drone's sideways slide is learnt (leaning left against a slide to the right)."""
    assert abs(_turning_past(DriftHold(PULSES, 5.0), 0.0)) < 0.02
    assert _turning_past(DriftHold(PULSES, 5.0), 0.3) < -0.1


def test_a_turn_gives_its_frame_to_a_lean_owed_up_to_its_cap() -> None:
    """Tracking a drifting drone's target turns in every frame: once the lean owed reaches its cap, a turn frame
    carries the lean instead, and the turns go on after it."""
    sticks = TrimSticks(PULSES, 5.0)
    frames = [sticks.shape(dp.turn_left(1474), 50 * k, -0.6, 0.0, 0.0) for k in range(60)]
    leans = [k for k, f in enumerate(frames) if lean_of(f)[0] < 0.0]
    assert leans and leans[0] * 0.05 * 0.6 >= DEBT_MAX_DEG_S - 0.05  # not before the cap
    assert len(leans) < 10 and sum(lean_of(f)[0] for f in frames[20:]) / 40 == pytest.approx(-0.6, abs=0.15)


def test_the_lead_is_what_the_recent_pitch_added() -> None:
    lead = Lead(0.8, lag_s=0.3)
    for _ in range(20):
        lead.advance(-1.0, 0.05)  # braking one step for a second
    assert lead.speed == pytest.approx(-0.8 * 0.3, abs=0.05)
    for _ in range(20):
        lead.advance(0.0, 0.05)
    assert lead.speed == 0.0


def test_the_controllers_own_pitch_is_not_paid_back_after_it() -> None:
    sticks = TrimSticks(PULSES, 5.0)
    for k in range(10):  # half a second of approach, no trim wanted
        sticks.shape(dp.move_forward(1600), 50 * k, 0.0, 0.0, 0.0)
    assert sticks.shape(dp.hold_altitude(), 500, 0.0, 0.0, 0.0) == dp.hold_altitude()


def test_aiming_at_a_target_that_slides_left_leans_left_in_the_holds() -> None:
    """AIM with the target sliding left in the frame (the drone drifting right): the controller learns a trim to
    the left and its holds carry it as roll; a still target teaches nothing."""
    c, rig = to_state(State.AIM, dataclasses.replace(CFG, aim_frames=1000))
    assert c.drift.drift.right == 0.0
    for _ in range(round(LATERAL_WINDOW_S / 0.05)):  # the rig's target jumps to the centre: the window forgets it
        rig.tick(seen(ex=0.0, size=0.2))
    learnt = c.drift.drift.right
    frames = [rig.tick(seen(ex=0.0, size=0.2)) for _ in range(40)]
    assert abs(c.drift.drift.right - learnt) < 0.005 and all(name(f) != "move_left" for f in frames if f is not None)
    c, rig = to_state(State.AIM, dataclasses.replace(CFG, aim_frames=1000))
    frames = [rig.tick(seen(ex=0.02 - 0.002 * k, size=0.2)) for k in range(40)]
    assert c.drift.drift.right < -0.02
    assert any(f is not None and name(f) == "move_left" for f in frames)


def test_a_closing_speed_right_after_the_pilots_own_pitch_teaches_no_forward_trim() -> None:
    """AIM brakes a drone still closing in from its approach: that speed is the approach's, not the drift's."""
    c, rig = to_state(State.AIM, dataclasses.replace(CFG, aim_frames=1000))
    r = 1.4
    for _ in range(20):
        r -= 0.03  # 0.6 m/s closer: the range hold brakes
        rig.tick(seen(size=size_at(r)))
    assert any(name(f) == "move_backward" for f in rig.sent) and c.drift.drift.forward == 0.0
