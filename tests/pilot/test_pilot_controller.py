"""Every transition of the controller's state machine, with an injected clock (no real time)."""

from __future__ import annotations

import dataclasses

import drone_protocol as dp
import pytest

from pilot.config import ControllerConfig
from pilot.controller import Controller, State
from pilot.detect import Detection
from pilot.detection import range_of

W, H = 320, 240
CFG = ControllerConfig()


class Clock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t

    def advance_ms(self, ms: float) -> None:
        self.t += ms / 1000.0


def seen(ex: float = 0.0, ey: float = 0.0, size: float = 0.05, confidence: float = 0.95) -> Detection:
    """A measured sighting of the 0.3 m ball, its range from its apparent size."""
    distance = range_of(size * W, 0.3, W, CFG.horizontal_fov_deg)
    return Detection(True, W / 2 + ex * W / 2, H / 2 + ey * H / 2, size * W, confidence, W, H, range_m=distance)


MISS = Detection(False, width=W, height=H)


def name(frame: bytes | None) -> str:
    assert frame is not None, "expected a command"
    return dp.decode(frame).name


def st(c: Controller) -> State:
    """The state, read through a call so that the type checker does not narrow it between updates."""
    return c.state


def tick(c: Controller, clock: Clock, det: Detection | None, ms: float = 50.0) -> bytes | None:
    out = c.update(det)
    clock.advance_ms(ms)
    return out


def to_state(state: State, cfg: ControllerConfig = CFG) -> tuple[Controller, Clock]:
    """Drive a fresh controller through the real transitions up to ``state``."""
    clock = Clock()
    c = Controller(cfg, clock=clock)
    c.start()
    order = [State.ARM, State.TAKEOFF, State.HOLD, State.SEARCH, State.ACQUIRE, State.TRACK, State.AIM, State.FIRE]
    for _ in range(2000):
        if st(c) is state:
            return c, clock
        if st(c) in (State.ARM, State.TAKEOFF, State.HOLD):
            tick(c, clock, MISS)
        elif st(c) in (State.SEARCH, State.ACQUIRE, State.TRACK):
            tick(c, clock, seen(size=0.3) if order.index(state) > order.index(State.TRACK) else seen())
        elif st(c) is State.AIM:
            tick(c, clock, seen(size=0.3))
        else:
            break
    raise AssertionError(f"did not reach {state}, stuck in {st(c)}")


def test_arm_takeoff_hold_search_timing() -> None:
    clock = Clock()
    c = Controller(CFG, clock=clock)
    assert st(c) is State.IDLE and c.update(MISS) is None
    c.start()
    assert st(c) is State.ARM
    assert name(tick(c, clock, MISS)) == "arm"
    # nothing new until the firmware's arming hold (from the spec) plus the margin has passed
    waited = 50
    while waited < dp.ARMING_HOLD_MS + CFG.arm_margin_ms:
        assert tick(c, clock, MISS) is None
        assert st(c) is State.ARM
        waited += 50
    out = tick(c, clock, MISS)
    assert st(c) is State.TAKEOFF and name(out) == "move_up"
    assert out is not None
    assert (dp.decode(out).value or 0) > dp.CHANNELS[dp.ChannelName.THROTTLE].median
    for _ in range(CFG.takeoff_ms // 50 - 1):
        assert name(tick(c, clock, MISS)) == "move_up"
    assert name(tick(c, clock, MISS)) == "hold_altitude" and st(c) is State.HOLD
    for _ in range(CFG.settle_ms // 50 - 1):
        assert name(tick(c, clock, MISS)) == "hold_altitude"
    assert name(tick(c, clock, MISS)) == "turn_right" and st(c) is State.SEARCH
    assert [t.new for t in c.transitions] == [State.ARM, State.TAKEOFF, State.HOLD, State.SEARCH]


def test_search_is_bounded_then_lands() -> None:
    c, clock = to_state(State.SEARCH)
    n = 0
    while st(c) is State.SEARCH:
        out = tick(c, clock, MISS, ms=100)
        n += 1
        if st(c) is State.SEARCH:
            assert name(out) == "turn_right"
    assert st(c) is State.LAND
    assert abs(n * 100 - CFG.search_max_ms) <= 100
    assert c.transitions[-1].reason == "search sweep exhausted"


def test_acquire_needs_consecutive_frames() -> None:
    c, clock = to_state(State.SEARCH)
    assert name(tick(c, clock, seen(0.3))) == "hold_altitude"  # stop turning
    assert st(c) is State.ACQUIRE
    # a flickering sighting: hits and misses alternate; never N in a row, so no tracking
    for _ in range(10):
        assert name(tick(c, clock, MISS)) == "hold_altitude"
        tick(c, clock, seen(0.3))
        assert st(c) is State.ACQUIRE
    for _ in range(CFG.acquire_frames - 2):
        tick(c, clock, seen(0.3))
        assert st(c) is State.ACQUIRE
    out = tick(c, clock, seen(0.3))
    assert st(c) is State.TRACK and name(out) == "turn_right"


def test_acquire_gives_up_after_missing_frames() -> None:
    c, clock = to_state(State.SEARCH)
    tick(c, clock, seen(0.3))
    for _ in range(CFG.lost_frames - 1):
        tick(c, clock, MISS)
        assert st(c) is State.ACQUIRE
    tick(c, clock, MISS)
    assert st(c) is State.SEARCH and c.transitions[-1].reason == "sighting not confirmed"


def test_unconfirmed_sightings_do_not_extend_the_sweep() -> None:
    c, clock = to_state(State.SEARCH)
    start = clock.t
    while st(c) is not State.LAND:
        # one sighting every second, never confirmed
        tick(c, clock, seen(0.3) if round((clock.t - start) * 20) % 20 == 0 else MISS)
        assert clock.t - start < CFG.search_max_ms / 1000.0 + 1.0, "the sweep must stay bounded"
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
    c, clock = to_state(State.TRACK)
    out = tick(c, clock, seen(ex, ey, size=0.05))
    assert st(c) is State.TRACK
    assert name(out) == expected
    assert out is not None
    value = dp.decode(out).value or 0
    spec = dp.COMMANDS[expected]
    median = dp.CHANNELS[spec.target].median
    assert spec.minimum <= value <= spec.maximum
    assert value != median


def test_track_coasts_through_a_few_missed_frames_only_when_approaching() -> None:
    c, clock = to_state(State.TRACK)
    forward = tick(c, clock, seen(size=0.05))
    assert name(forward) == "move_forward"
    coasted = [tick(c, clock, MISS) for _ in range(CFG.coast_frames)]
    assert coasted == [forward] * CFG.coast_frames
    assert name(tick(c, clock, MISS)) == "hold_altitude"  # then neutral until lost
    c, clock = to_state(State.TRACK)
    assert name(tick(c, clock, seen(0.4))) == "turn_right"
    assert name(tick(c, clock, MISS)) == "hold_altitude"  # no coasting on a turn


def test_turn_speed_grows_with_the_error() -> None:
    c, clock = to_state(State.TRACK)
    small = dp.decode(tick(c, clock, seen(0.15)) or b"").value
    large = dp.decode(tick(c, clock, seen(0.9)) or b"").value
    assert small is not None and large is not None
    assert dp.CHANNELS[dp.ChannelName.YAW].median < small < large


def test_track_to_aim_with_size_hysteresis() -> None:
    c, clock = to_state(State.TRACK)
    tick(c, clock, seen(size=CFG.approach_size * 0.99))
    assert st(c) is State.TRACK
    tick(c, clock, seen(size=CFG.approach_size))
    assert st(c) is State.AIM
    between = (CFG.approach_size + CFG.retreat_size) / 2
    tick(c, clock, seen(size=between))
    assert st(c) is State.AIM  # hysteresis: stays
    out = tick(c, clock, seen(size=CFG.retreat_size * 0.95))
    assert st(c) is State.TRACK and name(out) == "move_forward"


@pytest.mark.parametrize(
    "ex,ey,expected",
    [(0.3, 0.0, "servo_right"), (-0.3, 0.0, "servo_left"), (0.0, -0.3, "servo_up"), (0.0, 0.3, "servo_down")],
)
def test_aim_corrects_with_pan_tilt(ex: float, ey: float, expected: str) -> None:
    c, clock = to_state(State.AIM)
    out = tick(c, clock, seen(ex, ey, size=0.25))
    assert st(c) is State.AIM and name(out) == expected
    assert out is not None and 1 <= (dp.decode(out).value or 0) <= 180


def test_aim_then_fire_then_laser_timeout_then_land_and_disarm() -> None:
    c, clock = to_state(State.AIM)
    out = tick(c, clock, seen(0.3, size=0.25))  # off centre: a servo step, and the centred count restarts
    assert name(out) == "servo_right"
    for _ in range(CFG.aim_frames - 1):
        assert name(tick(c, clock, seen(size=0.25))) == "hold_altitude"
        assert not c.laser_on and st(c) is State.AIM
    out = tick(c, clock, seen(size=0.25))
    assert st(c) is State.FIRE and name(out) == "laser_toggle" and c.laser_on
    lit = 50
    while st(c) is State.FIRE:
        out = tick(c, clock, seen(size=0.25))
        lit += 50
        if st(c) is State.FIRE:
            assert name(out) == "hold_altitude"
    assert name(out) == "laser_toggle" and not c.laser_on  # off after the set time
    assert st(c) is State.LAND and c.fired
    assert abs(lit - CFG.fire_ms) <= 50
    frames = []
    while st(c) is State.LAND:
        frames.append(name(tick(c, clock, MISS)))
    assert st(c) is State.DONE
    assert frames[-1] == "disarm"
    assert set(frames[:-1]) <= {"move_down", "servo_reset"}
    assert tick(c, clock, MISS) is None


def test_laser_only_while_locked_and_centred() -> None:
    c, clock = to_state(State.FIRE)
    assert c.laser_on
    out = tick(c, clock, MISS)  # one missed frame: off at once, still firing
    assert name(out) == "laser_toggle" and not c.laser_on and st(c) is State.FIRE
    for _ in range(CFG.confirm_frames - 1):  # re-found and centred: confirmed again before the laser goes on
        assert name(tick(c, clock, seen(size=0.25))) == "hold_altitude" and not c.laser_on
    out = tick(c, clock, seen(size=0.25))
    assert name(out) == "laser_toggle" and c.laser_on
    out = tick(c, clock, seen(0.3, 0.0, size=0.25))  # off centre: off, back to aiming
    assert name(out) == "laser_toggle" and not c.laser_on and st(c) is State.AIM


def test_small_drift_while_firing_is_corrected_with_the_laser_on() -> None:
    c, clock = to_state(State.FIRE)
    drift = 1.5 * CFG.aim_tolerance  # beyond the aim tolerance, within the loose firing one
    out = tick(c, clock, seen(drift, size=0.25))
    assert name(out) == "servo_right" and c.laser_on and st(c) is State.FIRE
    out = tick(c, clock, seen(0.0, -drift, size=0.25))
    assert name(out) == "servo_up" and c.laser_on and st(c) is State.FIRE


@pytest.mark.parametrize("state", [State.TRACK, State.AIM, State.FIRE])
def test_target_lost_means_laser_off_neutral_and_search(state: State) -> None:
    c, clock = to_state(state)
    tick(c, clock, seen(-0.05, size=0.25 if state is not State.TRACK else 0.05))
    frames = [tick(c, clock, MISS) for _ in range(CFG.lost_frames)]
    assert st(c) is State.SEARCH
    assert not c.laser_on
    names = [name(f) for f in frames if f is not None]
    assert "hold_altitude" in names  # sticks neutral
    if state is State.FIRE:
        assert names[0] == "laser_toggle"
    # the sweep then turns towards the side the target was last seen on (left), servos homed first
    nxt = [name(tick(c, clock, MISS)) for _ in range(2)]
    assert nxt[-1] == "turn_left"
    assert c.transitions[-1].new is State.SEARCH and "lost" in c.transitions[-1].reason


def test_refound_after_loss_goes_through_acquire_again() -> None:
    c, clock = to_state(State.TRACK)
    for _ in range(CFG.lost_frames):
        tick(c, clock, MISS)
    assert st(c) is State.SEARCH
    tick(c, clock, seen(0.2))
    assert st(c) is State.ACQUIRE
    for _ in range(CFG.acquire_frames):
        tick(c, clock, seen(0.2))
    assert st(c) is State.TRACK


def test_failsafe_reply_switches_laser_belief_off_and_lands() -> None:
    c, _clock = to_state(State.FIRE)
    c.on_reply(dp.parse_reply(dp.failsafe_line()))
    assert not c.laser_on and st(c) is State.LAND
    assert "failsafe" in c.transitions[-1].reason


def test_not_armed_reply_lands() -> None:
    c, _clock = to_state(State.TRACK)
    c.on_reply(dp.parse_reply(dp.rejected_line(dp.ErrorKind.NOT_ARMED)))
    assert st(c) is State.LAND


def test_busy_reply_during_arming_is_ignored() -> None:
    c, _clock = to_state(State.ARM)
    c.on_reply(dp.parse_reply(dp.rejected_line(dp.ErrorKind.BUSY)))
    assert st(c) is State.ARM


def safe_names(c: Controller, clock: Clock, tick_ms: float = 50.0) -> list[str]:
    out = []
    for frame in c.safe_steps():
        out.append(name(frame))
        clock.advance_ms(tick_ms)
    return out


def test_safe_steps_with_laser_on_land_before_disarming() -> None:
    c, clock = to_state(State.FIRE)
    c.abort("test")
    assert st(c) is State.DONE
    names = safe_names(c, clock)
    assert names[:3] == ["laser_toggle", "hold_altitude", "servo_reset"]
    assert names[-1] == "disarm"
    downs = names[3:-1]
    assert set(downs) == {"move_down"}
    assert len(downs) == CFG.land_ms // 50  # down for the landing time, one frame per tick
    assert not c.laser_on


def test_safe_steps_with_laser_off_have_no_toggle() -> None:
    c, clock = to_state(State.TRACK)
    c.abort("test")
    names = safe_names(c, clock)
    assert names[:2] == ["hold_altitude", "servo_reset"] and names[-1] == "disarm"
    assert "laser_toggle" not in names


def test_safe_steps_on_the_ground_disarm_at_once() -> None:
    c, clock = to_state(State.ARM)
    c.abort("test")
    assert safe_names(c, clock) == ["hold_altitude", "servo_reset", "disarm"]


def test_safe_steps_are_bounded_when_the_clock_stands_still() -> None:
    c, _clock = to_state(State.TRACK)
    c.abort("test")
    names = [name(f) for f in c.safe_steps()]  # the clock never advances
    assert names[-1] == "disarm" and len(names) <= CFG.land_ms // 5 + 4


def test_config_changes_take_effect() -> None:
    cfg = dataclasses.replace(CFG, acquire_frames=1, fire_ms=200)
    c, clock = to_state(State.SEARCH, cfg)
    tick(c, clock, seen())
    assert st(c) is State.TRACK  # one frame is enough
    c, clock = to_state(State.FIRE, cfg)
    for _ in range(4):
        tick(c, clock, seen(size=0.3))
    assert st(c) is State.LAND
