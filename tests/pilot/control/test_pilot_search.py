"""SEARCH's look at a glimpse (``search.Look``): a sighting measured under the acquire confidence stops the sweep
for a while, and the sweep then turns on before another; an injected clock, no real time."""

from __future__ import annotations

from controller_rig import CFG, MISS, name, seen, st, to_state

from pilot.control.controller import State
from pilot.control.search import GLIMPSE_SHARE, LOOK_AGAIN_MS, LOOK_MS, Look

UNDER = 0.5 * (GLIMPSE_SHARE + 1.0) * CFG.acquire_confidence  # a glimpse: at least the share, under the level


def test_a_look_holds_then_the_sweep_turns_on_before_another() -> None:
    look = Look()
    assert not look.holds(0, glimpse=False)
    assert look.holds(100, glimpse=True)
    assert look.holds(100 + LOOK_MS - 1, glimpse=False)  # held whatever the frames show
    assert not look.holds(100 + LOOK_MS, glimpse=True)  # over, and no other look at once
    assert not look.holds(100 + LOOK_MS + LOOK_AGAIN_MS - 1, glimpse=True)
    assert look.holds(100 + LOOK_MS + LOOK_AGAIN_MS, glimpse=True)


def test_the_sweep_stops_at_a_glimpse_and_turns_gently_after_it() -> None:
    c, rig = to_state(State.SEARCH)
    for _ in range(40):  # past the search's first frames (a servo reset)
        assert name(rig.tick(MISS)) == "turn_right"
    # the turn's blur: measured, under the acquire confidence; the sweep used to turn on past it
    assert name(rig.tick(seen(0.05, confidence=UNDER))) == "hold_altitude"
    assert st(c) is State.SEARCH
    assert name(rig.tick(seen(-0.4, confidence=UNDER))) == "turn_left"  # after it, where the stop carried it
    for _ in range(LOOK_MS // 50 - 2):
        assert name(rig.tick(MISS)) == "hold_altitude"
    assert name(rig.tick(MISS)) == "turn_right"  # the look is over: the sweep again
    assert name(rig.tick(seen(0.0, confidence=UNDER))) == "turn_right"  # ... for a while, whatever it glimpses


def test_a_faint_or_bridged_sighting_is_no_glimpse() -> None:
    c, rig = to_state(State.SEARCH)
    for _ in range(40):
        rig.tick(MISS)
    faint = seen(0.0, confidence=0.9 * GLIMPSE_SHARE * CFG.acquire_confidence)
    assert name(rig.tick(faint)) == "turn_right"
    bridged = seen(0.0, confidence=UNDER)
    object.__setattr__(bridged, "predicted", True)
    assert name(rig.tick(bridged)) == "turn_right"
    assert st(c) is State.SEARCH
