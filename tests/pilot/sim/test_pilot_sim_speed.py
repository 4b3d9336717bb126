"""The simulator's speed probe (bench/flight/speed.py): physics per tick of simulated time, render and sensor per
frame, and a baseline that is not a checkout refused in one line; a campaign resumed from its log."""

from __future__ import annotations

from pathlib import Path

import pytest

from bench.flight.run import main, pending
from bench.flight.speed import figures
from pilot.app.sim_flight import FlightJob


def test_physics_counts_per_tick_and_the_camera_per_frame() -> None:
    # a flight that looked for 8 s (160 frames) and then landed blind for 2 s more: 200 ticks of physics
    flight = {"physics_ms": 400.0, "render_ms": 1600.0, "sensor_ms": 160.0, "frames": 160, "sim_seconds": 10.0,
              "wall_seconds": 20.0}
    f = figures([flight, flight])
    assert (f.physics_ms, f.render_ms, f.sensor_ms) == pytest.approx((2.0, 10.0, 1.0))
    assert f.factor == pytest.approx(50.0 / 13.0) and f.loop == pytest.approx(0.5)


def test_a_baseline_that_is_not_a_checkout_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["--speed-only", "--speed-baseline", str(tmp_path)])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert "--speed-baseline" in err and "not a checkout" in err
    assert not (tmp_path / "SPEED.md").exists()


def test_a_resumed_campaign_flies_only_the_flights_its_log_lacks(tmp_path: Path) -> None:
    todo = [FlightJob("ahead", 3019, "aruco"), FlightJob("behind", 3019, "aruco"), FlightJob("ahead", 3019, "hsv"),
            FlightJob("ahead", 4019, "hsv", gusts=0.5)]
    log = tmp_path / "held-out.jsonl"
    log.write_text('{"scenario": "ahead", "seed": 3019, "detector": "aruco", "gusts": 0.0}\n\n'
                   '{"scenario": "ahead", "seed": 4019, "detector": "hsv", "gusts": 0.5}\n')
    assert pending(todo, log) == todo[1:3]
