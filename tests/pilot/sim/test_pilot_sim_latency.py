"""Latency in the simulated world (pilot/sim/latency.py): a frame shows the room as it was at its exposure, a
dropped frame is one camera period older, and the pan/tilt servos slew at their rated speed."""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

from pilot.sim.camera import CameraModel, Image
from pilot.sim.latency import FrameTiming, Servos
from pilot.sim.randomise import CAMERA_FPS, Effects
from pilot.sim.room import make_scenario
from pilot.sim.virtual import VirtualDrone
from pilot.sim.world import SimWorld


@contextmanager
def _world(exe: Path, effects: Effects) -> Iterator[SimWorld]:
    sc = dataclasses.replace(make_scenario("moving_target", 1, ideal=True), effects=effects)
    with VirtualDrone(exe) as vd, SimWorld(sc, vd, CameraModel(160, 120)) as world:
        yield world


def _frame_at(exe: Path, ms: int, effects: Effects) -> Image:
    with _world(exe, effects) as world:
        world.advance(ms)
        return world.render()


def test_a_frame_shows_the_room_as_it_was_at_its_exposure(virtual_drone: Path) -> None:
    late = _frame_at(virtual_drone, 3000, Effects(frame_latency_s=0.1))
    then = _frame_at(virtual_drone, 2900, Effects())
    now = _frame_at(virtual_drone, 3000, Effects())
    assert np.array_equal(late, then)  # the target moved meanwhile: the frame shows where it was 100 ms before
    assert not np.array_equal(late, now)


def test_rendering_the_past_leaves_the_present_as_it_was(virtual_drone: Path) -> None:
    with _world(virtual_drone, Effects(frame_latency_s=0.1)) as world:
        world.advance(2000)
        before = [*world.target_position(), *world.sensor.axis()[0], *world.mj_data.qpos]
        world.render()
        after = [*world.target_position(), *world.sensor.axis()[0], *world.mj_data.qpos]
        assert after == pytest.approx(before, abs=1e-9)  # (MuJoCo's step leaves positions of the step's start)


def test_a_dropped_frame_is_one_camera_period_older() -> None:
    timing = FrameTiming(Effects(frame_latency_s=0.05, frame_drop=0.3), seed=4)
    ages = [round(t - timing.exposure(t), 6) for t in np.arange(0.0, 50.0, 0.05)]
    assert set(ages) == {0.05, round(0.05 + 1.0 / CAMERA_FPS, 6)}
    assert 0.25 < timing.dropped / len(ages) < 0.35
    assert FrameTiming(Effects(frame_latency_s=0.05), seed=4).exposure(1.0) == pytest.approx(0.95)


def test_the_servos_slew_at_their_rated_speed() -> None:
    servos = Servos(Effects(servo_s_per_60deg=0.15), 90.0, 90.0)
    steps = 0
    while servos.step(150.0, 60.0, 0.002):
        steps += 1
    assert steps * 0.002 == pytest.approx(0.15, abs=0.003)  # 60 degrees in 0.15 s; the tilt's 30 in half that
    assert (servos.pan, servos.tilt) == (150.0, 60.0)
    ideal = Servos(Effects(), 90.0, 90.0)
    assert ideal.step(150.0, 60.0, 0.002) and (ideal.pan, ideal.tilt) == (150.0, 60.0)
