"""The lock's hysteresis (``lock.py``): once tracked, a target stays sighted at a lower confidence while it stays the
same steady thing; acquiring it and lighting it need what they needed before. Injected clock, no real time."""

from __future__ import annotations

from controller_rig import CFG, name, seen, st, to_state

from pilot.control.controller import State
from pilot.control.lock import KEEP_SHARE, Lock

WEAK = 0.5 * (KEEP_SHARE + 1.0) * CFG.acquire_confidence  # kept, not acquired
FAINT = 0.9 * KEEP_SHARE * CFG.acquire_confidence


def test_a_tracked_target_under_the_acquire_confidence_is_not_lost() -> None:
    c, rig = to_state(State.TRACK)
    rig.tick(seen(0.3, size=0.05))
    for _ in range(3 * CFG.lost_frames):  # a ball braked towards, low in the frame: 0.52-0.58 (ahead 3016)
        assert name(rig.tick(seen(0.3, size=0.05, confidence=WEAK))) == "turn_right"
        assert st(c) is State.TRACK


def test_a_lock_is_not_kept_on_something_else_or_on_a_faint_sighting() -> None:
    for weak in (seen(-0.6, size=0.05, confidence=WEAK), seen(0.3, size=0.05, confidence=FAINT)):
        c, rig = to_state(State.TRACK)
        rig.tick(seen(0.3, size=0.05))
        for _ in range(CFG.lost_frames):
            rig.tick(weak)
        assert st(c) is State.SEARCH and c.transitions[-1].reason == "target lost while tracking"


def test_only_a_lock_is_kept() -> None:
    lock = Lock()
    strong, weak = seen(0.1), seen(0.1, confidence=WEAK)
    assert not lock.sighted(weak, acquired=False, locked=True, acquire_confidence=CFG.acquire_confidence)
    assert lock.sighted(strong, acquired=True, locked=False, acquire_confidence=CFG.acquire_confidence)
    assert not lock.sighted(weak, acquired=False, locked=False, acquire_confidence=CFG.acquire_confidence)
    assert lock.sighted(strong, acquired=True, locked=True, acquire_confidence=CFG.acquire_confidence)
    assert lock.sighted(weak, acquired=False, locked=True, acquire_confidence=CFG.acquire_confidence)
    assert not lock.sighted(None, acquired=False, locked=True, acquire_confidence=CFG.acquire_confidence)
    assert not lock.sighted(weak, acquired=False, locked=True, acquire_confidence=CFG.acquire_confidence)


def test_a_kept_lock_never_lights_the_laser() -> None:
    c, rig = to_state(State.AIM)
    rig.tick(seen(0.0, size=CFG.approach_size * 1.05))
    for _ in range(4 * CFG.aim_frames):
        rig.tick(seen(0.0, size=CFG.approach_size * 1.05, confidence=WEAK))
        assert st(c) is State.AIM and not c.want_laser


def test_a_sighting_acquired_once_is_confirmed_by_steady_frames_under_the_level() -> None:
    c, rig = to_state(State.SEARCH)
    rig.tick(seen(0.3, size=0.05))  # acquired at the full confidence: ACQUIRE
    assert st(c) is State.ACQUIRE
    for _ in range(CFG.acquire_frames - 1):  # then 0.46-0.6, the same ball (high 3011)
        rig.tick(seen(0.3, size=0.05, confidence=WEAK))
    assert st(c) is State.TRACK and c.transitions[-1].reason.startswith("seen in")
