"""The approach without position hold: the closing speed from the detector's ranges, braking, holding the
range near the target, and braking by dead reckoning when the target is lost while closing in."""

from __future__ import annotations

import dataclasses
import math

import drone_protocol as dp
import pytest
from controller_rig import CFG, MISS, Rig, name, seen, size_at, st, to_state

from pilot.control.approach import ClosingSpeed, Lean, allowed_speed
from pilot.control.controller import MIN_BRAKE, Controller, State
from pilot.control.pulses import StickModel


def test_closing_speed_is_the_slope_of_the_ranges() -> None:
    est = ClosingSpeed()
    assert est.closing is None
    for k in range(10):
        est.update(k * 0.05, 3.0 - 0.5 * k * 0.05)  # 0.5 m/s closer every second
    assert est.closing == pytest.approx(0.5)
    est.update(0.55, float("nan"))  # no range: ignored
    assert est.closing == pytest.approx(0.5)
    est.reset()
    assert est.closing is None
    assert allowed_speed(0.0, 0.5, 0.6) == 0.0 and allowed_speed(10.0, 0.5, 0.6) == 0.6


def test_aim_brakes_a_closing_drone_and_nudges_a_receding_one() -> None:
    c, rig = to_state(State.AIM, dataclasses.replace(CFG, aim_frames=100))  # stays aiming
    r = 1.3
    out = None
    for _ in range(6):
        r -= 0.05  # 1 m/s closer
        out = rig.tick(seen(size=size_at(r)))
    assert st(c) is State.AIM and name(out) == "move_backward"
    c.closing.reset()
    for _ in range(6):
        r += 0.03  # 0.6 m/s away, still above the retreat size
        out = rig.tick(seen(size=size_at(r)))
    assert st(c) is State.AIM and name(out) == "move_forward"


def test_track_coasts_or_brakes_when_closing_faster_than_it_can_stop() -> None:
    c, rig = to_state(State.TRACK)
    r = 2.2
    outs = []
    for _ in range(6):
        r -= 0.1  # 2 m/s closer: far above what 0.5 m/s² stops before the aim range
        outs.append(name(rig.tick(seen(size=size_at(r)))))
    assert st(c) is State.TRACK and outs[-1] == "move_backward"


def lost_while_closing() -> tuple[Controller, Rig, float]:
    """TRACK closing in at 0.8 m/s from 3 m, then the target lost until the search begins; and the last range."""
    c, rig = to_state(State.TRACK)
    r = 3.0
    for _ in range(6):
        r -= 0.04  # 0.8 m/s closer
        rig.tick(seen(size=size_at(r)))
    while st(c) is not State.SEARCH:
        rig.tick(MISS)
    return c, rig, r


def test_lost_while_closing_brakes_before_the_search_turns() -> None:
    _, rig, _ = lost_while_closing()
    assert name(rig.tick(MISS)) == "move_backward"  # braking first ...
    turns = [name(rig.tick(MISS)) for _ in range(60)]
    assert turns[-1] in ("turn_left", "turn_right")  # ... then the sweep
    assert dp.COMMANDS[dp.CommandName.MOVE_BACKWARD].target == "pitch"


def test_a_sighting_while_braking_at_a_loss_does_not_end_the_brake() -> None:
    """A half-covered target flickers: lost while closing in, then seen every other frame, never confirmed.
    Confirming a sighting goes on with the brake planned at the loss (neutral sticks would coast the drone into
    the cover), for that brake's time and no longer."""
    c, rig, r = lost_while_closing()
    outs, states = [], set()
    for k in range(60):
        outs.append(name(rig.tick(seen(size=size_at(r)) if k % 2 else MISS)))
        states.add(st(c))
    assert State.ACQUIRE in states  # the sightings were taken up
    brakes = outs.index(next(o for o in outs if o != "move_backward"))
    # about 0.55 m/s (0.8 less its standard error: six ranges of a 28 px ball) at the brake's deceleration, plus
    # the lean's lag
    assert brakes * 50 >= 600, outs
    assert "move_backward" not in outs[brakes:], outs  # then hovering and sweeping, no brake held on


def test_a_target_that_stops_shrinking_before_it_is_lost_still_gets_its_brake() -> None:
    """Going out of sight, a target's last frames can read a constant range (covered or clipped, it looks
    smaller than it is): the brake at the loss follows the last 1.2 s of ranges, not only the last 0.4 s."""
    c, rig = to_state(State.TRACK)
    r = 3.0
    for _ in range(16):
        r -= 0.03  # 0.6 m/s closer for 0.8 s ...
        rig.tick(seen(size=size_at(r)))
    for _ in range(9):
        rig.tick(seen(size=size_at(r)))  # ... then 0.45 s of one range
    assert c.closing.closing is not None and c.closing.closing < 0.15
    while st(c) is not State.SEARCH:
        rig.tick(MISS)
    brakes = 0
    while name(rig.tick(MISS)) == "move_backward":
        brakes += 1
    assert brakes * 50 >= 600  # the trend: about 0.4 m/s, 0.6 s at the brake's deceleration (vision alone: 0.15 m/s)


def test_a_target_covered_while_the_drone_pushes_forward_still_gets_the_brake_its_commands_call_for() -> None:
    """A target sliding behind a cover reads the same size for its last frames while the drone, pitched forward,
    flies on: vision's speed and its 1.2 s trend both drop, the commands' own reckoning does not."""
    c, rig = to_state(State.TRACK)
    r = 3.0
    for _ in range(30):  # 1.5 s of one range, and TRACK pushing forward all along
        rig.tick(seen(size=size_at(r)))
    assert c.closing.closing is not None and abs(c.closing.closing) < 0.05
    assert c.reckoned.speed > 0.5
    while st(c) is not State.SEARCH:
        rig.tick(MISS)
    speed = c.reckoned.speed
    brakes = 0
    while name(rig.tick(MISS)) == "move_backward":
        brakes += 1
    # vision's estimate alone gave no brake at all; this one lasts as long as its own deceleration needs to stop
    # that speed, plus the lean's lag, and no longer (held on, it would fly the drone backwards)
    stop_s = speed / (CFG.pitch_accel_mps2 * min(1.4, 0.8 + speed)) + c.lean.lag_s
    assert abs(brakes * 0.05 - stop_s) <= 0.1


def test_the_lean_follows_the_pitch_stick_with_a_lag() -> None:
    lean = Lean(CFG.pitch_accel_mps2)
    assert lean.deg_per_step == pytest.approx(math.degrees(math.atan(CFG.pitch_accel_mps2 / 9.81)))
    lean.advance(2.0, lean.lag_s)
    assert lean.deg == pytest.approx(2.0 * lean.deg_per_step * (1.0 - math.exp(-1.0)))
    for _ in range(40):  # 2 s: ten lags
        lean.advance(-1.0, 0.05)
    assert lean.deg == pytest.approx(-lean.deg_per_step, abs=0.01)


def brake_us(ey: float) -> int:
    c, rig = to_state(State.AIM, dataclasses.replace(CFG, aim_frames=100))
    r, out = 1.3, None
    for _ in range(6):
        r -= 0.05  # 1 m/s closer
        out = rig.tick(seen(0.0, ey, size=size_at(r)))
    assert st(c) is State.AIM and name(out) == "move_backward"
    return abs(dp.decode(out or b"").value or 0)


def test_a_brake_keeps_a_low_target_in_the_frame() -> None:
    """A brake pitches the nose up and the target down the frame: near the frame's lower edge it brakes
    gentler (never below the gentlest brake) rather than lose it."""
    median = dp.CHANNELS[dp.ChannelName.PITCH].median
    centred, low = median - brake_us(0.0), median - brake_us(0.5)
    assert 0 < low < centred
    assert low >= round(MIN_BRAKE * StickModel().unit_us(dp.ChannelName.PITCH, False))




def test_a_far_targets_ranges_give_a_loss_no_brake_they_do_not_show_for_certain() -> None:
    """A far ball's apparent size jitters by half a pixel, its range by 0.15 m at 5 m: four ranges over 0.15 s can
    fit 1.1 m/s closing on a drone closing at 0.16 (``distractor`` 3012 braked on such a fit, then at the loss
    again, and flew backwards into the north wall). At a loss, vision's speed counts less its standard error, which
    the ball's size sets: the same four ranges 2.5 m away brake, 5 m away they do not."""

    def brake_s(far: float) -> tuple[float, float]:
        """The brake's length at the loss, and how long the commands' own reckoning alone would brake."""
        c, rig = to_state(State.TRACK)
        rig.tick(seen(size=size_at(far + 1.0)))  # a jump: the fit starts again from the next range
        for k in range(4):
            rig.tick(seen(size=size_at(far - 0.055 * k)))  # 1.1 m/s closer
        assert c.closing.closing == pytest.approx(1.1, abs=0.05)
        while st(c) is not State.SEARCH:
            rig.tick(MISS)
        reckoned = c.reckoned.speed  # TRACK's own forward pitch, about 0.3 m/s
        stop_s = reckoned / (CFG.pitch_accel_mps2 * min(1.4, 0.8 + reckoned)) + c.lean.lag_s
        return [name(rig.tick(MISS)) for _ in range(60)].count("move_backward") * 0.05, stop_s

    near, commanded = brake_s(2.5)
    assert near >= commanded + 0.3  # vision's 1.1 m/s, less 0.35
    far, commanded = brake_s(5.0)
    assert abs(far - commanded) <= 0.1  # vision's, less 1.3, is no speed at all


def test_track_brakes_for_the_closing_speed_the_ranges_show_for_certain() -> None:
    """The same four ranges fitting 1.1 m/s: 2.5 m away TRACK brakes on them, 5 m away (a 17 px ball, each range
    0.15 m in error) it does not (``distractor`` 3012 braked 0.3 s at 6 m on such a fit while closing at 0.16)."""

    def first_move(far: float) -> str:
        c, rig = to_state(State.TRACK)
        rig.tick(seen(size=size_at(far + 1.0)))
        out = None
        for k in range(4):
            out = rig.tick(seen(size=size_at(far - 0.055 * k)))
        assert st(c) is State.TRACK and c.closing.closing == pytest.approx(1.1, abs=0.05)
        return str(name(out))

    assert first_move(2.5) == "move_backward"
    assert first_move(5.0) != "move_backward"
