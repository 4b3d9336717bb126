"""The controller's state machine from firing to landing: the laser, a lost target, the drone's refusals and
failsafe, aborts and the landing routine (tests/pilot/controller_rig.py)."""

from __future__ import annotations

import dataclasses

import drone_protocol as dp
import pytest
from controller_rig import CFG, MISS, Clock, land_to_done, name, refusal, seen, st, to_state

from pilot.control.controller import Controller, State
from pilot.control.descent import LAND_FROM_M

N = dp.CommandName


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
    assert frames[0] == "servo_reset"
    routine = frames.index("land")  # the pilot's own descent first (see the next test)
    assert set(frames[1:routine]) == {"move_down"}
    # the firmware's landing routine, then only status polls
    assert "disarm" not in frames and set(frames[routine:]) <= {"land", "query_status"}
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
    # as the firmware does, the next frame after the failsafe (laser off) leaves it for disarmed
    assert c.drone.safe and drone_state(c) is dp.DroneState.DISARMED and "confirmed" in c.transitions[-1].reason


def drone_state(c: Controller) -> dp.DroneState | None:
    """The confirmed state, read through a call (an attribute read keeps the type an earlier assert narrowed)."""
    return c.drone.state


def test_not_armed_reply_lands() -> None:
    c, _rig = to_state(State.TRACK)
    c.on_reply(refusal(dp.ErrorKind.NOT_ARMED, dp.DroneState.DISARMED))
    assert st(c) is State.LAND


def test_busy_reply_during_arming_is_ignored() -> None:
    c, _rig = to_state(State.ARM)
    c.on_reply(refusal(dp.ErrorKind.BUSY, dp.DroneState.ARMING))
    assert st(c) is State.ARM


def test_the_pilot_descends_itself_to_near_the_floor_before_the_landing_routine() -> None:
    """The landing routine descends slowly with roll and pitch centred, and a trim drift of 0.5 m/s carried the
    drone into walls on the way down: after its fire the pilot descends itself at twice that speed to
    ``LAND_FROM_M`` by its height estimate, then hands over to the routine, whose time limit starts then."""
    c, rig = to_state(State.FIRE)
    start_m = c.height.m
    assert start_m > 1.0  # the take-off's climb
    while st(c) is State.FIRE:
        rig.tick(seen(size=0.3))
    assert st(c) is State.LAND and c.fired
    frames: list[str] = []
    while not frames or frames[-1] != "land":
        out = rig.tick(MISS)
        if out is not None:
            frames.append(name(out))
        assert len(frames) < 200
    assert frames[-2] == "move_down" and frames.count("move_down") >= 10
    assert c.height.settles_m <= LAND_FROM_M + 0.05
    land_to_done(rig)
    assert c.drone.safe and "confirmed disarmed" in c.transitions[-1].reason


def test_a_stop_during_the_pilots_descent_hands_over_to_the_landing_routine_at_once() -> None:
    """Asked to stop (again) while descending: no more of the pilot's own descent, the firmware's routine now."""
    c, rig = to_state(State.FIRE)
    while st(c) is State.FIRE:
        rig.tick(seen(size=0.3))
    assert name(rig.tick(MISS)) in ("move_down", "hold_altitude", "servo_reset")
    c.emergency()
    frames = land_to_done(rig)
    assert "move_down" not in frames and frames[0] in ("servo_reset", "land")


def test_abort_while_firing_lands_and_waits_for_the_drone() -> None:
    c, rig = to_state(State.FIRE)
    c.abort("test")
    assert st(c) is State.LAND and not c.want_laser
    frames = land_to_done(rig)
    ordered = [f for f in frames if f not in ("servo_reset", "query_status")]  # servos home only if moved
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
    assert name(c.update(None)) == "query_status"  # status polls while it disarms
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
    while name(out := c.update(None)) in ("servo_reset", "query_status"):
        rig.clock.advance_ms(50)
        waited += 50
        assert waited <= dp.LANDING_MS + 100
    assert name(out) == "disarm" and waited >= dp.LANDING_MS - 50
    c.on_reply(refusal(dp.ErrorKind.BUSY, dp.DroneState.DISARMING))
    c.on_reply(refusal(dp.ErrorKind.NOT_ARMED, dp.DroneState.DISARMED))
    assert c.update(None) is None and st(c) is State.DONE and c.drone.safe
