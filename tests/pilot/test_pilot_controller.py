"""Every transition of the controller's state machine, with an injected clock (no real time), flying a
fake drone that answers with the spec's status (tests/pilot/fake_drone.py)."""

from __future__ import annotations

import dataclasses

import drone_protocol as dp
import pytest
from fake_drone import FakeDrone

from pilot.config import ControllerConfig
from pilot.controller import Controller, State
from pilot.detect import Detection
from pilot.detection import range_of

W, H = 320, 240
CFG = ControllerConfig()
N = dp.CommandName
KEEPALIVE_MS = 200


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


class Rig:
    """The runner's tick against the fake drone: replies first, then the decision, then the wire (with
    the runner's keep-alive when the controller has nothing to say)."""

    def __init__(self, cfg: ControllerConfig = CFG, drone: FakeDrone | None = None) -> None:
        self.clock = Clock()
        self.drone = drone or FakeDrone(self.clock)
        self.c = Controller(cfg, clock=self.clock)
        self.sent: list[bytes] = []
        self._last_send = -1e9

    def tick(self, det: Detection | None, ms: float = 50.0) -> bytes | None:
        for reply in self.drone.poll():
            self.c.on_reply(reply)
        out = self.c.update(det)
        wire = out
        if wire is None and st(self.c) is not State.DONE and self.clock.t - self._last_send >= KEEPALIVE_MS / 1000:
            wire = dp.hold_altitude()
        if wire is not None:
            self.drone.send(wire)
            self.sent.append(wire)
            self._last_send = self.clock.t
        self.clock.advance_ms(ms)
        return out


def to_state(state: State, cfg: ControllerConfig = CFG) -> tuple[Controller, Rig]:
    """Drive a fresh controller through the real transitions up to ``state``."""
    rig = Rig(cfg)
    c = rig.c
    c.start()
    order = [State.ARM, State.TAKEOFF, State.HOLD, State.SEARCH, State.ACQUIRE, State.TRACK, State.AIM, State.FIRE]
    for _ in range(2000):
        if st(c) is state:
            if state is State.FIRE:  # the drone's reply has confirmed the laser on
                rig.tick(seen(size=0.3))
            return c, rig
        if st(c) in (State.ARM, State.TAKEOFF, State.HOLD):
            rig.tick(MISS)
        elif st(c) in (State.SEARCH, State.ACQUIRE, State.TRACK):
            rig.tick(seen(size=0.3) if order.index(state) > order.index(State.TRACK) else seen())
        elif st(c) is State.AIM:
            rig.tick(seen(size=0.3))
        else:
            break
    raise AssertionError(f"did not reach {state}, stuck in {st(c)}")


def refusal(error: dp.ErrorKind, state: dp.DroneState) -> dp.Reply:
    """A rejected reply with the drone's status (laser off)."""
    return dp.parse_reply(dp.rejected_line(error, state, False))


def land_to_done(rig: Rig, limit_s: float = 30.0) -> list[str]:
    """Tick through LAND (no target) until DONE; the frames the controller chose."""
    out = []
    start = rig.clock.t
    while st(rig.c) is not State.DONE:
        frame = rig.tick(MISS)
        if frame is not None:
            out.append(name(frame))
        assert rig.clock.t - start < limit_s
    return out


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
            assert name(out) == "hold_altitude", "the arm frame arrived: status polls until the drone confirms"
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
            assert name(out) == "turn_right"
    assert st(c) is State.LAND
    assert abs(n * 100 - CFG.search_max_ms) <= 100
    assert c.transitions[-1].reason == "search sweep exhausted"


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


def test_fire_lights_by_confirmation_then_lands_through_the_firmware_routine() -> None:
    c, rig = to_state(State.AIM)
    out = rig.tick(seen(0.3, size=0.25))  # off centre: a servo step, and the centred count restarts
    assert name(out) == "servo_right"
    for _ in range(CFG.aim_frames - 1):
        assert name(rig.tick(seen(size=0.25))) == "hold_altitude"
        assert c.want_laser is False and st(c) is State.AIM
    out = rig.tick(seen(size=0.25))
    assert st(c) is State.FIRE and name(out) == "laser_on" and c.want_laser
    assert c.laser_on is False  # not yet confirmed: the reply comes with the next tick
    rig.tick(seen(size=0.25))
    assert c.laser_on is True and rig.drone.laser
    while st(c) is State.FIRE:
        out = rig.tick(seen(size=0.25))
        if st(c) is State.FIRE:
            assert name(out) == "hold_altitude"
    assert name(out) == "laser_off" and st(c) is State.LAND and c.fired
    assert abs(c.lit_ms - CFG.fire_ms) <= 50
    frames = land_to_done(rig)
    assert frames[:2] == ["servo_reset", "land"]  # the firmware's landing routine, then only status polls
    assert "disarm" not in frames and set(frames[2:]) <= {"land", "hold_altitude"}
    assert rig.drone.state is dp.DroneState.DISARMED and not rig.drone.laser
    assert c.drone.safe and "confirmed disarmed" in c.transitions[-1].reason
    assert "laser_toggle" not in [name(f) for f in rig.sent]


def test_laser_only_while_locked_and_centred() -> None:
    c, rig = to_state(State.FIRE)
    assert c.laser_on
    out = rig.tick(MISS)  # one missed frame: off at once, still firing
    assert name(out) == "laser_off" and not c.want_laser and st(c) is State.FIRE
    for _ in range(CFG.confirm_frames - 1):  # re-found and centred: confirmed again before the laser goes on
        assert name(rig.tick(seen(size=0.25))) == "hold_altitude" and not c.want_laser
    out = rig.tick(seen(size=0.25))
    assert name(out) == "laser_on" and c.want_laser
    out = rig.tick(seen(0.3, 0.0, size=0.25))  # off centre: off, back to aiming
    assert name(out) == "laser_off" and not c.want_laser and st(c) is State.AIM


def test_small_drift_while_firing_is_corrected_with_the_laser_on() -> None:
    c, rig = to_state(State.FIRE)
    drift = 1.5 * CFG.aim_tolerance  # beyond the aim tolerance, within the loose firing one
    out = rig.tick(seen(drift, size=0.25))
    assert name(out) == "servo_right" and c.laser_on and st(c) is State.FIRE
    out = rig.tick(seen(0.0, -drift, size=0.25))
    assert name(out) == "servo_up" and c.laser_on and st(c) is State.FIRE


def test_a_lost_laser_off_is_sent_again_within_one_reply_round_trip() -> None:
    _c, rig = to_state(State.FIRE)
    rig.drone.drop_frames = 1
    assert name(rig.tick(MISS)) == "laser_off"  # lost on the way
    assert rig.drone.laser
    out = rig.tick(MISS)  # that tick's reply (to the frame before) still says on
    assert name(out) == "laser_off" and not rig.drone.laser


def test_the_drone_reporting_its_laser_on_is_corrected_at_once() -> None:
    c, rig = to_state(State.TRACK)
    rig.drone.laser = True  # say a corrupted frame switched it on
    rig.tick(seen())  # this tick's frame gets a reply with "laser on"
    assert name(rig.tick(seen())) == "laser_off" and st(c) is State.TRACK
    rig.tick(seen())
    assert c.laser_on is False and not rig.drone.laser


def test_a_lost_reply_changes_nothing_but_a_lost_frame_is_repaired() -> None:
    c, rig = to_state(State.FIRE)
    rig.drone.drop_replies = 3
    for _ in range(3):
        rig.tick(seen(size=0.3))
    assert c.laser_on is True and st(c) is State.FIRE


@pytest.mark.parametrize("state", [State.TRACK, State.AIM, State.FIRE])
def test_target_lost_means_laser_off_neutral_and_search(state: State) -> None:
    c, rig = to_state(state)
    rig.tick(seen(-0.05, size=0.25 if state is not State.TRACK else 0.05))
    frames = [rig.tick(MISS) for _ in range(CFG.lost_frames)]
    assert st(c) is State.SEARCH
    assert not c.want_laser and c.laser_on is False
    names = [name(f) for f in frames if f is not None]
    assert "hold_altitude" in names  # sticks neutral
    if state is State.FIRE:
        assert names[0] == "laser_off"
    # the sweep then turns towards the side the target was last seen on (left), servos homed first (and after a
    # forward approach, braking first: test_pilot_approach.py)
    nxt = [name(rig.tick(MISS)) for _ in range(60)]
    assert "turn_left" in nxt and "turn_right" not in nxt
    assert set(nxt[: nxt.index("turn_left")]) <= {"servo_reset", "move_backward"}
    assert c.transitions[-1].new is State.SEARCH and "lost" in c.transitions[-1].reason


def test_refound_after_loss_goes_through_acquire_again() -> None:
    c, rig = to_state(State.TRACK)
    for _ in range(CFG.lost_frames):
        rig.tick(MISS)
    assert st(c) is State.SEARCH
    rig.tick(seen(0.2))
    assert st(c) is State.ACQUIRE
    for _ in range(CFG.acquire_frames):
        rig.tick(seen(0.2))
    assert st(c) is State.TRACK


def test_failsafe_reply_lands_and_the_drone_confirms_laser_off() -> None:
    c, rig = to_state(State.FIRE)
    rig.clock.advance_ms(dp.FAILSAFE_TIMEOUT_MS)  # the link went quiet
    rig.tick(seen(size=0.3))
    assert st(c) is State.LAND and "failsafe" in c.transitions[-1].reason
    assert c.laser_on is False and c.drone.state is dp.DroneState.FAILSAFE
    land_to_done(rig)
    assert c.drone.safe and "failsafe" in c.transitions[-1].reason


def test_not_armed_reply_lands() -> None:
    c, _rig = to_state(State.TRACK)
    c.on_reply(refusal(dp.ErrorKind.NOT_ARMED, dp.DroneState.DISARMED))
    assert st(c) is State.LAND


def test_busy_reply_during_arming_is_ignored() -> None:
    c, _rig = to_state(State.ARM)
    c.on_reply(refusal(dp.ErrorKind.BUSY, dp.DroneState.ARMING))
    assert st(c) is State.ARM


def test_abort_while_firing_lands_and_waits_for_the_drone() -> None:
    c, rig = to_state(State.FIRE)
    c.abort("test")
    assert st(c) is State.LAND and not c.want_laser
    frames = land_to_done(rig)
    ordered = [f for f in frames if f not in ("servo_reset", "hold_altitude")]  # servos home only if moved
    assert ordered == ["laser_off", "land"]
    assert rig.drone.state is dp.DroneState.DISARMED and c.drone.safe
    # the firmware's landing routine and disarm sequence ran, and nothing after the drone confirmed
    assert rig.drone.log[-1][1] is dp.DroneState.DISARMED


def test_abort_on_the_ground_disarms_plainly() -> None:
    c, rig = to_state(State.ARM)
    rig.tick(MISS)
    c.on_reply(refusal(dp.ErrorKind.BUSY, dp.DroneState.ARMED))  # armed, not yet flying
    c.abort("test")
    assert name(c.update(None)) == "disarm"
    c.on_reply(refusal(dp.ErrorKind.BUSY, dp.DroneState.DISARMING))
    assert name(c.update(None)) == "hold_altitude"  # status polls while it disarms
    c.on_reply(refusal(dp.ErrorKind.NOT_ARMED, dp.DroneState.DISARMED))
    assert c.update(None) is None and st(c) is State.DONE and c.drone.safe


def test_disarm_refused_as_airborne_lands_instead() -> None:
    c, _rig = to_state(State.TRACK)
    c.abort("test")
    c.on_reply(refusal(dp.ErrorKind.BUSY, dp.DroneState.ARMED))
    assert name(c.update(None)) == "disarm"
    c.on_reply(refusal(dp.ErrorKind.AIRBORNE, dp.DroneState.ARMED))
    assert name(c.update(None)) == "land"


def test_landing_gives_up_when_the_drone_never_confirms() -> None:
    c, rig = to_state(State.TRACK)
    rig.drone.stop_answering = True
    c.abort("test")
    start = rig.clock.t
    land_to_done(rig)
    assert abs((rig.clock.t - start) * 1000 - CFG.land_ms) <= 100
    assert "did not confirm" in c.transitions[-1].reason and not c.drone.safe


def test_emergency_stops_after_the_failsafe_time_without_an_answer() -> None:
    c, rig = to_state(State.TRACK)
    c.abort("test")
    rig.tick(MISS)
    rig.drone.stop_answering = True
    c.emergency()
    start = rig.clock.t
    frames = land_to_done(rig)
    assert "servo_reset" not in frames  # the shortest sequence
    assert (rig.clock.t - start) * 1000 <= dp.FAILSAFE_TIMEOUT_MS + 100


def test_dry_run_without_replies_arms_by_time_and_lands_once() -> None:
    clock = Clock()
    c = Controller(CFG, clock=clock)
    c.start()
    sent = []
    for _ in range(2000):
        out = c.update(MISS)
        if out is not None:
            sent.append(name(out))
        clock.advance_ms(50)
        if st(c) is State.SEARCH:
            c.abort("test")
        if st(c) is State.DONE:
            break
    assert sent[0] == "arm" and sent.count("arm") == 1
    assert sent[-1] == "land" and sent.count("land") == 1
    assert c.laser_on is None and "no status" in c.transitions[-1].reason


def test_config_changes_take_effect() -> None:
    cfg = dataclasses.replace(CFG, acquire_frames=1, fire_ms=200)
    c, rig = to_state(State.SEARCH, cfg)
    rig.tick(seen())
    assert st(c) is State.TRACK  # one frame is enough
    c, rig = to_state(State.FIRE, cfg)
    for _ in range(4):
        rig.tick(seen(size=0.3))
    assert st(c) is State.LAND


def test_a_board_that_reports_disarmed_without_disarming_still_gets_the_disarm_sticks() -> None:
    """A rebooted board says "disarmed" while the flight controller may still be armed: once it is down
    (the landing routine's time), the disarm sequence goes out anyway."""
    c, rig = to_state(State.TRACK)
    c.on_reply(refusal(dp.ErrorKind.NOT_ARMED, dp.DroneState.DISARMED))  # straight from moving to disarmed
    assert st(c) is State.LAND
    waited = 0
    while name(out := c.update(None)) in ("servo_reset", "hold_altitude"):
        rig.clock.advance_ms(50)
        waited += 50
        assert waited <= dp.LANDING_MS + 100
    assert name(out) == "disarm" and waited >= dp.LANDING_MS - 50
    c.on_reply(refusal(dp.ErrorKind.BUSY, dp.DroneState.DISARMING))
    c.on_reply(refusal(dp.ErrorKind.NOT_ARMED, dp.DroneState.DISARMED))
    assert c.update(None) is None and st(c) is State.DONE and c.drone.safe
