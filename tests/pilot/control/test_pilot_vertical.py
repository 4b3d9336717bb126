"""The heights the target was seen from (pilot/control/vertical.py): a target hidden by a climb is approached
from below."""

from __future__ import annotations

import pytest
from controller_rig import CFG, MISS, name, seen, st, to_state

from pilot.control.controller import State
from pilot.control.vertical import APPROACH_FLOOR_M, KEEP_IN_VIEW, MARGIN_M, MIN_LIMIT_M, Height, SeenFrom


def test_the_height_follows_the_throttle_stick_with_a_lag() -> None:
    h = Height(0.5, lag_s=0.2)
    for _ in range(40):  # 2 s at one speed step up
        h.advance(1.0, 0.05)
    assert h.rate == pytest.approx(0.5, rel=1e-3)
    assert h.m == pytest.approx(0.5 * (2.0 - 0.2), abs=0.02)  # the lag costs about lag_s of climbing
    settles = h.settles_m
    for _ in range(40):  # released: it slows down and stops where settles_m said
        h.advance(0.0, 0.05)
    assert h.rate == pytest.approx(0.0, abs=1e-3)
    assert h.m == pytest.approx(settles, abs=0.01)
    for _ in range(20):
        h.advance(-2.0, 0.05)
    assert h.rate < 0.0 and h.m < settles


def test_a_target_lost_after_a_climb_sets_a_ceiling_below_where_it_was_seen() -> None:
    s = SeenFrom()
    s.saw(1.0)
    s.lost(1.0)  # lost where it was seen (a turn, an occluder passing): no limit
    assert s.ceiling_m is None and s.floor_m is None and s.return_to() == 1.0
    s.lost(1.3)
    assert s.ceiling_m == pytest.approx(1.0 - MARGIN_M)
    assert s.return_to() == pytest.approx(1.0 - MARGIN_M)
    assert s.barred(True, 0.95, -0.3) and not s.barred(False, 0.95, 0.3)
    assert not s.barred(True, 0.8, -0.3)  # below the ceiling it may still climb
    assert not s.barred(True, 0.95, -(KEEP_IN_VIEW + 0.1))  # about to leave the frame: followed all the same


def test_a_descent_sets_a_floor_and_the_newer_limit_wins() -> None:
    s = SeenFrom()
    s.saw(1.0)
    s.lost(1.3)
    s.saw(0.6)
    s.lost(0.4)
    assert s.floor_m == pytest.approx(0.6 + MARGIN_M) and s.ceiling_m == pytest.approx(1.0 - MARGIN_M)
    assert s.barred(False, 0.7, 0.2) and s.return_to() == pytest.approx(0.6 + MARGIN_M)
    s.saw(1.2)
    s.lost(1.0)  # a floor above the ceiling: the ceiling goes
    assert s.floor_m == pytest.approx(1.2 + MARGIN_M) and s.ceiling_m is None


def test_no_ceiling_from_a_sighting_near_the_ground() -> None:
    s = SeenFrom()
    s.saw(MIN_LIMIT_M / 2)  # seen from the ground, lost on take-off
    s.lost(1.2)
    assert s.ceiling_m is None


def test_a_target_lost_as_the_drone_climbs_to_it_is_approached_from_below() -> None:
    """TRACK climbs towards a target above the frame's centre; it is lost (hidden from above): the search goes
    back down before it turns, and the target found again is approached without the climb."""
    c, rig = to_state(State.TRACK)
    above = seen(0.0, -0.4, size=0.08)
    climbs = 0
    while name(rig.tick(above)) == "move_up":
        climbs += 1
        if climbs == 20:
            break
    assert climbs == 20
    while st(c) is not State.SEARCH:
        rig.tick(MISS)
    downs = 0
    while (out := name(rig.tick(MISS))) == "move_down":
        downs += 1
    assert downs > 0 and out == "turn_right"  # back down first, then the sweep
    assert c.height.settles_m <= c.seen_from.return_to() + 0.06  # type: ignore[operator]
    while st(c) is not State.TRACK:
        rig.tick(above)
    assert {name(rig.tick(above)) for _ in range(5)} <= {"move_forward", "hold_altitude"}


def test_the_throttle_estimate_ignores_servo_and_laser_frames() -> None:
    c, rig = to_state(State.AIM)
    before = c.height.settles_m
    for _ in range(10):
        rig.tick(seen(0.0, 0.3, size=0.25))  # servo steps
    assert c.height.settles_m == pytest.approx(before, abs=1e-6)
    assert CFG.climb_mps_per_step > 0.0


def test_a_low_target_is_approached_from_above_the_floor_height() -> None:
    """Never seen lower: TRACK still descends no lower than ``APPROACH_FLOOR_M`` towards a low target (AIM tilts
    down to it), unless the target is about to leave the frame's bottom."""
    s = SeenFrom()
    assert s.barred(False, APPROACH_FLOOR_M, 0.3) and s.barred(False, APPROACH_FLOOR_M - 0.2, 0.3)
    assert not s.barred(False, APPROACH_FLOOR_M + 0.05, 0.3) and not s.barred(True, APPROACH_FLOOR_M, -0.3)
    assert not s.barred(False, APPROACH_FLOOR_M, KEEP_IN_VIEW + 0.1)
