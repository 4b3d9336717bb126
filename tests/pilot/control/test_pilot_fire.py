"""Firing: the fire time is one unbroken stay of the laser on the target."""

from __future__ import annotations

from controller_rig import CFG, MISS, seen, st, to_state

from pilot.control.controller import State


def test_the_fire_time_is_one_unbroken_stay_on_the_target() -> None:
    """A miss while firing switches the laser off and starts the count again: 1 s lit, a miss, then 1 s lit again
    is not a completed 1.5 s fire (it was, counted cumulatively); another 0.6 s makes it one."""
    c, rig = to_state(State.FIRE)
    for _ in range(20):
        rig.tick(seen(size=0.3))
    assert c.lit_ms >= 900 and not c.fired
    rig.tick(MISS)
    for _ in range(20):
        rig.tick(seen(size=0.3))
    assert st(c) is State.FIRE and not c.fired and c.lit_ms < CFG.fire_ms
    for _ in range(15):
        rig.tick(seen(size=0.3))
    assert c.fired and st(c) is State.LAND
