"""The controller's state machine from arming to aiming, with an injected clock (no real time), flying a fake
drone that answers with the spec's status (tests/pilot/controller_rig.py)."""

from __future__ import annotations

import dataclasses

import drone_protocol as dp
import pytest
from controller_rig import CFG, MISS, Rig, land_to_done, name, seen, st, to_state
from fake_drone import FakeDrone

from pilot.control.controller import State

N = dp.CommandName


def test_arm_waits_for_the_drone_to_confirm_it_then_takes_off() -> None:
    rig = Rig()
    c = rig.c
    assert st(c) is State.IDLE and c.update(MISS) is None
    c.start()
    assert name(rig.tick(MISS)) == "arm"
    assert c.drone.state is None  # nothing confirmed yet
    ticks = 0
    while st(c) is State.ARM:
        out = rig.tick(MISS)
        ticks += 1
        if st(c) is State.ARM:
            # the arm frame arrived: status queries until the drone confirms, AltHold once it is armed
            assert name(out) == ("hold_altitude" if c.drone.state is dp.DroneState.ARMED else "query_status")
            assert c.drone.state is dp.DroneState.ARMING or c.drone.state in dp.ARMED_STATES
    assert st(c) is State.TAKEOFF and name(out) == "move_up"
    assert out is not None and dp.decode(out).value > dp.CHANNELS[dp.ChannelName.THROTTLE].median
    # confirmed armed after the firmware's hold, then the margin
    assert abs(ticks * 50 - (dp.ARMING_HOLD_MS + CFG.arm_margin_ms)) <= 100
    assert "confirmed armed" in c.transitions[-1].reason
    for _ in range(CFG.takeoff_ms // 50 - 1):
        assert name(rig.tick(MISS)) == "move_up"
    assert name(rig.tick(MISS)) == "hold_altitude" and st(c) is State.HOLD
    for _ in range(CFG.settle_ms // 50 - 1):
        assert name(rig.tick(MISS)) == "hold_altitude"
    assert name(rig.tick(MISS)) == "turn_right" and st(c) is State.SEARCH
    assert [t.new for t in c.transitions] == [State.ARM, State.TAKEOFF, State.HOLD, State.SEARCH]


def test_a_lost_arm_frame_is_sent_again_when_the_drone_says_disarmed() -> None:
    rig = Rig()
    rig.drone.drop_frames = 1  # the first arm never arrives
    rig.c.start()
    assert name(rig.tick(MISS)) == "arm"
    frames = [rig.tick(MISS) for _ in range(10)]  # keep-alives are answered "not armed, disarmed"
    assert [name(f) for f in frames if f is not None][:1] == ["arm"]
    while st(rig.c) is State.ARM:
        rig.tick(MISS)
    assert st(rig.c) is State.TAKEOFF and rig.drone.state in dp.ARMED_STATES


def test_arming_never_confirmed_gives_up_without_flying() -> None:
    class Stubborn(FakeDrone):
        def _handle(self, name: dp.CommandName) -> dp.ErrorKind | None:
            return dp.ErrorKind.BUSY if name is N.ARM else super()._handle(name)

    rig = Rig()
    rig.drone = Stubborn(rig.clock)
    rig.c.start()
    sent = land_to_done(rig)
    assert set(sent) == {"arm"}  # again and again, never a movement
    assert any("never confirmed armed" in t.reason for t in rig.c.transitions)
    assert rig.c.drone.safe and "disarmed" in rig.c.transitions[-1].reason


def test_search_is_bounded_then_lands() -> None:
    c, rig = to_state(State.SEARCH)
    n = 0
    while st(c) is State.SEARCH:
        out = rig.tick(MISS, ms=100)
        n += 1
        if st(c) is State.SEARCH:
            assert name(out) in ("turn_right", "move_down", "move_up")
    assert st(c) is State.LAND
    assert abs(n * 100 - CFG.search_max_ms) <= 100
    assert c.transitions[-1].reason == "search sweep exhausted"


def test_search_sweeps_again_one_step_lower_then_one_step_higher() -> None:
    """Something in front of the target may hide it from one height: each leg of the sweep is flown at
    another (start, one step below, one step above), with full-stick climbs and descents between."""
    cfg = dataclasses.replace(CFG, search_max_ms=4 * CFG.search_leg_ms)
    c, rig = to_state(State.SEARCH, cfg)
    runs: list[tuple[str, int]] = []  # (command, ms) in the order sent, equal neighbours merged
    while True:
        out = name(rig.tick(MISS, ms=50))
        if st(c) is not State.SEARCH:
            break
        if runs and runs[-1][0] == out:
            runs[-1] = (out, runs[-1][1] + 50)
        else:
            runs.append((out, 50))
    legs = [(cmd, ms) for cmd, ms in runs if cmd != "turn_right"]
    step = cfg.search_step_ms
    assert [cmd for cmd, _ in legs] == ["move_down", "move_up", "move_down"]
    for (_, ms), want in zip(legs, (step, 2 * step, 2 * step), strict=True):
        assert abs(ms - want) <= 50
    turns = [ms for cmd, ms in runs if cmd == "turn_right"]
    assert all(abs(ms - cfg.search_leg_ms) <= 100 for ms in turns[1:-1])  # whole legs between the steps


def test_acquire_needs_consecutive_frames() -> None:
    c, rig = to_state(State.SEARCH)
    assert name(rig.tick(seen(0.3))) == "hold_altitude"  # stop turning
    assert st(c) is State.ACQUIRE
    # a flickering sighting: hits and misses alternate; never N in a row, so no tracking
    for _ in range(10):
        assert name(rig.tick(MISS)) == "hold_altitude"
        rig.tick(seen(0.3))
        assert st(c) is State.ACQUIRE
    for _ in range(CFG.acquire_frames - 2):
        rig.tick(seen(0.3))
        assert st(c) is State.ACQUIRE
    out = rig.tick(seen(0.3))
    assert st(c) is State.TRACK and name(out) == "turn_right"


def test_acquire_gives_up_after_missing_frames() -> None:
    c, rig = to_state(State.SEARCH)
    rig.tick(seen(0.3))
    for _ in range(CFG.lost_frames - 1):
        rig.tick(MISS)
        assert st(c) is State.ACQUIRE
    rig.tick(MISS)
    assert st(c) is State.SEARCH and c.transitions[-1].reason == "sighting not confirmed"


def test_unconfirmed_sightings_do_not_extend_the_sweep() -> None:
    c, rig = to_state(State.SEARCH)
    start = rig.clock.t
    while st(c) is not State.LAND:
        # one sighting every second, never confirmed
        rig.tick(seen(0.3) if round((rig.clock.t - start) * 20) % 20 == 0 else MISS)
        assert rig.clock.t - start < CFG.search_max_ms / 1000.0 + 1.0, "the sweep must stay bounded"
    assert c.transitions[-1].reason == "search sweep exhausted"


@pytest.mark.parametrize(
    "ex,ey,expected",
    [
        (0.4, 0.0, "turn_right"),
        (-0.4, 0.0, "turn_left"),
        (0.0, -0.5, "move_up"),
        (0.0, 0.5, "move_down"),
        (0.0, 0.0, "move_forward"),
        (CFG.dead_band_x * 0.9, CFG.dead_band_y * 0.9, "move_forward"),  # inside both dead bands
        (0.4, 0.5, "turn_right"),  # yaw first
    ],
)
def test_track_dead_bands(ex: float, ey: float, expected: str) -> None:
    c, rig = to_state(State.TRACK)
    out = rig.tick(seen(ex, ey, size=0.05))
    assert st(c) is State.TRACK
    assert name(out) == expected
    assert out is not None
    value = dp.decode(out).value or 0
    spec = dp.COMMANDS[dp.CommandName(expected)]
    median = dp.CHANNELS[dp.ChannelName(spec.target)].median
    assert spec.minimum <= value <= spec.maximum
    assert value != median


def test_track_coasts_through_a_few_missed_frames_only_when_approaching() -> None:
    _c, rig = to_state(State.TRACK)
    forward = rig.tick(seen(size=0.05))
    assert name(forward) == "move_forward"
    coasted = [rig.tick(MISS) for _ in range(CFG.coast_frames)]
    assert coasted == [forward] * CFG.coast_frames
    assert name(rig.tick(MISS)) == "hold_altitude"  # then neutral until lost
    _c, rig = to_state(State.TRACK)
    assert name(rig.tick(seen(0.4))) == "turn_right"
    assert name(rig.tick(MISS)) == "hold_altitude"  # no coasting on a turn


def test_turn_speed_grows_with_the_error() -> None:
    _c, rig = to_state(State.TRACK)
    small = dp.decode(rig.tick(seen(0.15)) or b"").value
    large = dp.decode(rig.tick(seen(0.9)) or b"").value
    assert small is not None and large is not None
    assert dp.CHANNELS[dp.ChannelName.YAW].median < small < large


def test_track_to_aim_with_size_hysteresis() -> None:
    c, rig = to_state(State.TRACK)
    rig.tick(seen(size=CFG.approach_size * 0.99))
    assert st(c) is State.TRACK
    rig.tick(seen(size=CFG.approach_size))
    assert st(c) is State.AIM
    between = (CFG.approach_size + CFG.retreat_size) / 2
    rig.tick(seen(size=between))
    assert st(c) is State.AIM  # hysteresis: stays
    out = rig.tick(seen(size=CFG.retreat_size * 0.95))
    assert st(c) is State.TRACK and name(out) == "move_forward"


def test_aim_steps_the_servos_only_on_measured_sightings() -> None:
    """A servo step's swing can blur the target away for a frame or two: the tracker's prediction through them
    knows nothing of the step, so acting on it would repeat the step (and overshoot)."""
    c, rig = to_state(State.AIM)
    low = seen(0.0, 0.3, size=0.25)
    assert name(rig.tick(low)) == "servo_down"
    bridged = dataclasses.replace(low, predicted=True, confidence=0.8)
    assert [name(rig.tick(bridged)) for _ in range(2)] == ["hold_altitude"] * 2
    assert st(c) is State.AIM
    assert name(rig.tick(low)) == "hold_altitude"  # measured, but 150 ms after the step: it may not show yet
    assert name(rig.tick(low)) == "servo_down"  # 200 ms: still needed, so repeated


def test_a_servo_step_is_not_repeated_before_a_late_frame_can_show_it() -> None:
    """Frames reach the pilot up to 120 ms after their exposure and the servo slews: the frames just after a step
    still show the old error. Stepping on them repeats the step (three of them where one was due, and the spot
    overshoots the target); a frame that shows more error the same way gets only the difference."""
    _c, rig = to_state(State.AIM)
    low = seen(0.0, 0.3, size=0.25)
    first = rig.tick(low)
    assert first is not None and dp.decode(first).name == "servo_down"
    step = dp.decode(first).value
    assert [name(rig.tick(low)) for _ in range(3)] == ["hold_altitude"] * 3
    lower = seen(0.0, 0.6, size=0.25)
    more = rig.tick(lower)  # 200 ms on: the whole of the new error, the first step now shows in any frame
    assert more is not None and dp.decode(more).name == "servo_down" and dp.decode(more).value > step
    again = rig.tick(seen(0.0, 0.9, size=0.25))  # further still the same way: only the rest beyond the last step
    assert again is not None and dp.decode(again).name == "servo_down"
    assert dp.decode(again).value < dp.decode(more).value
    assert name(rig.tick(seen(0.0, -0.3, size=0.25))) == "hold_altitude"  # never back while a step may not show


def test_aim_backs_off_a_target_it_coasted_up_to_before_it_fires() -> None:
    c, rig = to_state(State.AIM)
    close = seen(size=CFG.back_off_size * 1.2)
    outs = [name(rig.tick(close)) for _ in range(CFG.aim_frames + 2)]
    assert st(c) is State.AIM and "move_backward" in outs and "laser_on" not in outs


@pytest.mark.parametrize(
    "ex,ey,expected",
    [(0.3, 0.0, "servo_right"), (-0.3, 0.0, "servo_left"), (0.0, -0.3, "servo_up"), (0.0, 0.3, "servo_down")],
)
def test_aim_corrects_with_pan_tilt(ex: float, ey: float, expected: str) -> None:
    c, rig = to_state(State.AIM)
    out = rig.tick(seen(ex, ey, size=0.25))
    assert st(c) is State.AIM and name(out) == expected
    assert out is not None and 1 <= (dp.decode(out).value or 0) <= 180
