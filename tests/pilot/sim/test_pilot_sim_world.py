"""The randomised world (pilot/sim/randomise.py): drawn per seed, off with ``ideal``, every figure checked against
its physical range; scenarios refused when the spawn or the target lies in something; the airframe's variation,
its trim drift and the barometric height AltHold holds."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from sim_rig import PARAMS, Rig

from pilot.common.errors import ConfigError
from pilot.sim import mj, rc
from pilot.sim.placement import check
from pilot.sim.randomise import DRAWN, IDEAL, Effects, draw
from pilot.sim.room import make_scenario
from pilot.sim.scenario import Prop
from pilot.sim.scene import build


def test_a_world_is_drawn_per_seed_within_its_ranges_and_ideal_turns_it_off() -> None:
    a, b, c = draw("ahead", 3), draw("ahead", 3), draw("ahead", 4)
    assert a == b and a != c
    for name, (lo, hi) in DRAWN.items():
        if name != "readout_s" or a.picam:  # a USB webcam's shutter is global
            assert lo <= getattr(a, name) <= hi, name
    assert {draw("ahead", s).picam for s in range(8)} == {0.0, 1.0}
    assert draw("ahead", 3, ideal=True) == IDEAL and IDEAL.ideal and not a.ideal
    assert make_scenario("ahead", 3).effects == a
    assert make_scenario("ahead", 3, ideal=True).effects == IDEAL


@pytest.mark.parametrize(("field", "value"), [("mass_scale", -1.0), ("frame_latency_s", -0.01),
                                              ("servo_s_per_60deg", math.nan), ("frame_drop", 0.9)])
def test_a_parameter_outside_its_physical_range_is_refused_naming_it(field: str, value: float) -> None:
    with pytest.raises(ConfigError, match=f"simulator parameter {field} = .*outside its physical range"):
        Effects(**{field: value})
    with pytest.raises(ConfigError, match=f"simulator parameter {field} = "):
        draw("ahead", 1, overrides={field: value})
    with pytest.raises(ConfigError, match="'weight': unknown"):
        draw("ahead", 1, overrides={"weight": 1.0})


def test_a_flight_controller_or_airframe_figure_outside_its_range_is_refused(tmp_path: Path,
                                                                             monkeypatch: pytest.MonkeyPatch) -> None:
    with pytest.raises(ConfigError, match=r"simulator parameter THR_DZ = 1200 .*outside its physical range 0\.\.300"):
        rc.load(overrides={"THR_DZ": 1200.0})
    text = rc.PARAMS_YAML.read_text().replace("mass_kg: 1.5", "mass_kg: -1.5")
    (tmp_path / "arducopter.yaml").write_text(text)
    monkeypatch.setattr(rc, "PARAMS_YAML", tmp_path / "arducopter.yaml")
    with pytest.raises(ConfigError, match=r"simulator parameter airframe.mass_kg = -1.5 .*physical range"):
        rc.load()
    # a copy of the code without the generated parameter file flies no other flight controller in silence
    with pytest.raises(ConfigError, match=r"parameter file .*drone\.parm is missing"):
        rc.load(tmp_path / "drone.parm")


def test_a_spawn_or_target_inside_a_wall_or_furniture_is_refused_when_the_room_is_built() -> None:
    sc = make_scenario("ahead", 2)
    check(sc)
    in_wall = dataclasses.replace(sc, start=(0.1, 4.0, 0.0))
    with pytest.raises(ConfigError, match=r"scenario 'ahead' seed 2: the spawn point \(0.10, 4.00\)"):
        build(in_wall, PARAMS.airframe, 64, 48, 45.0)
    tx, ty, tz = sc.target.position
    cabinet = Prop("box", (tx, ty, tz), (0.4, 0.4, tz), (0.5, 0.5, 0.5))
    with pytest.raises(ConfigError, match=r"the target at .* lies inside prop_\d+ \(box"):
        build(dataclasses.replace(sc, props=(*sc.props, cabinet)), PARAMS.airframe, 64, 48, 45.0)
    sx, sy, _ = sc.start
    chair = Prop("cylinder", (sx + 0.2, sy, 0.4), (0.2, 0.4, 0.0), (0.8, 0.1, 0.1), distractor=True)
    with pytest.raises(ConfigError, match=r"the spawn point .* lies inside distractor_\d+ \(cylinder"):
        check(dataclasses.replace(sc, props=(*sc.props, chair)))
    high = dataclasses.replace(sc, target=dataclasses.replace(sc.target, position=(tx, ty, 2.95)))
    with pytest.raises(ConfigError, match="lies in a wall, the floor or the ceiling"):
        check(high)


def test_mass_thrust_drag_and_motor_lag_vary_with_the_world() -> None:
    e = Effects(mass_scale=1.2, thrust_scale=0.85, drag_scale=0.9, motor_tau_scale=1.1)
    a, v = PARAMS.airframe, PARAMS.varied(e).airframe
    assert (v.mass_kg, v.motor_max_n) == pytest.approx((a.mass_kg * 1.2, a.motor_max_n * 0.85))
    assert (v.drag_linear, v.drag_quadratic, v.motor_tau_s) == pytest.approx(
        (a.drag_linear * 0.9, a.drag_quadratic * 0.9, a.motor_tau_s * 1.1))
    rig = Rig(effects=e).airborne()  # AltHold still holds it: the flight controller learns its hover throttle
    mujoco = mj.module()
    body = mujoco.mj_name2id(rig.model, mujoco.mjtObj.mjOBJ_BODY, "drone")
    assert rig.model.body_mass[body] == pytest.approx(v.mass_kg)
    assert rig.af.fc.hover == pytest.approx(v.mass_kg * 9.81 / (4 * v.motor_max_n))


def _speed_after(effects: Effects, seconds: float) -> tuple[float, float]:
    """The airframe's horizontal velocity along and across its nose after ``seconds`` of centred sticks."""
    rig = Rig(effects=effects).airborne()
    rig.run(seconds)
    h = rig.af.state.heading
    v = np.asarray(rig.data.qvel[0:2])
    return float(v @ [math.cos(h), math.sin(h)]), float(v @ [-math.sin(h), math.cos(h)])


def test_a_trim_error_drifts_the_airframe_with_centred_sticks() -> None:
    assert max(abs(v) for v in _speed_after(IDEAL, 6.0)) < 0.05
    along, across = _speed_after(Effects(drift_mps=0.4, drift_heading=math.pi / 2), 6.0)  # to the left
    assert across == pytest.approx(0.4, abs=0.08) and abs(along) < 0.08


def test_althold_holds_the_barometric_height_not_the_true_one() -> None:
    rig = Rig(effects=Effects(baro_drift_m=0.5)).airborne()
    z0, err0 = rig.af.state.z, rig.af.estimator.height_error
    rig.run(20.0)
    moved, drifted = rig.af.state.z - z0, rig.af.estimator.height_error - err0
    assert abs(drifted) > 0.1  # the barometer wandered ...
    assert moved == pytest.approx(-drifted, abs=0.08)  # ... and the airframe with it: the estimate stayed put


def test_the_barometer_reads_low_in_the_ground_effect_with_the_motors_on() -> None:
    rig = Rig(effects=Effects(ground_effect_m=0.3))
    rig.run(0.2)
    assert rig.af.estimator.height_error == 0.0  # disarmed: the motors are off
    rig.airborne()
    assert rig.af.estimator.height_error == 0.0  # above the wash's reach
    rig.af.estimator.height(0.0, True, 0.002)
    assert rig.af.estimator.height_error == pytest.approx(-0.3)


class _Flown(Exception):
    pass


@pytest.mark.parametrize(("argv", "ideal"), [(["--ideal"], True), ([], False)])
def test_the_ideal_flag_turns_the_world_s_effects_off_for_the_flight(monkeypatch: pytest.MonkeyPatch,
                                                                    argv: list[str], ideal: bool) -> None:
    from pilot.app import cli, sim_flight

    seen: dict[str, object] = {}

    def fake_fly(*args: object, **kwargs: object) -> None:
        seen.update(kwargs)
        raise _Flown

    monkeypatch.setattr(sim_flight, "fly", fake_fly)
    with pytest.raises(_Flown):
        cli.main([*argv, "--no-status"])
    assert seen["ideal"] is ideal
