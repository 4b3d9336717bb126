"""The simulated motor mixer keeps ArduCopter's priorities: roll and pitch before yaw, attitude before the
collective."""

from __future__ import annotations

import math

import pytest
from sim_rig import CH, PARAMS, Rig

from pilot.sim.mixer import Mixer
from pilot.sim.scene import MOTOR_SPIN, motor_positions

FRAME = PARAMS.airframe
FLOOR = PARAMS["MOT_SPIN_MIN"] * FRAME.motor_max_n
TOP = FRAME.motor_max_n
HOVER = FRAME.mass_kg * 9.81


def mixer(headroom: float = PARAMS["MOT_YAW_HEADROOM"]) -> Mixer:
    return Mixer(FRAME.arm_m, FRAME.yaw_moment_m, FLOOR, TOP, headroom)


def wrench(thrusts: list[float]) -> tuple[float, float, float, float]:
    """Collective force and the roll, pitch and yaw torques four thrusts make (FLU)."""
    pos = motor_positions(FRAME.arm_m)
    return (sum(thrusts),
            sum(t * y for t, (_, y) in zip(thrusts, pos, strict=True)),
            sum(-t * x for t, (x, _) in zip(thrusts, pos, strict=True)),
            sum(t * s * FRAME.yaw_moment_m for t, s in zip(thrusts, MOTOR_SPIN, strict=True)))


def test_a_demand_within_the_motors_range_is_met_exactly() -> None:
    demand = (HOVER, 0.3, -0.2, 0.05)
    thrusts = mixer().thrusts(*demand)
    assert all(FLOOR <= t <= TOP for t in thrusts)
    assert wrench(thrusts) == pytest.approx(demand, abs=1e-9)


def test_a_yaw_demand_past_the_motors_authority_leaves_roll_and_pitch_whole() -> None:
    """A wall touch spins the airframe: the yaw demand saturates, and the lean the airframe needs still comes."""
    thrusts = mixer().thrusts(HOVER, 0.4, -0.3, 2.0)
    force, roll, pitch, yaw = wrench(thrusts)
    assert all(FLOOR - 1e-9 <= t <= TOP + 1e-9 for t in thrusts)
    assert (roll, pitch) == pytest.approx((0.4, -0.3), abs=1e-9)
    assert 0.0 < yaw < 2.0  # what is left goes to yaw, in its sense
    assert force == pytest.approx(HOVER, rel=0.05)


def test_the_yaw_headroom_is_kept_even_when_roll_and_pitch_take_everything() -> None:
    full_roll = 10.0  # more than four motors can make: roll, pitch and yaw are scaled down together
    without = wrench(mixer(0.0).thrusts(HOVER, full_roll, 0.0, 1.0))
    kept = wrench(mixer().thrusts(HOVER, full_roll, 0.0, 1.0))
    assert without[3] == pytest.approx(0.0, abs=1e-9) and kept[3] > 0.0
    assert 0.0 < kept[1] < full_roll


def test_attitude_comes_before_the_collective_near_the_top() -> None:
    thrusts = mixer().thrusts(4 * TOP, 0.5, 0.0, 0.0)  # full collective and a roll demand
    force, roll, _, _ = wrench(thrusts)
    assert roll == pytest.approx(0.5, abs=1e-9) and force < 4 * TOP
    assert max(thrusts) == pytest.approx(TOP)


def test_a_wall_touch_while_turning_leaves_the_airframe_upright() -> None:
    """Blown into a wall at 0.4 m/s mid-turn (a search in gusts): the touch spins the airframe, the saturated
    yaw demand no longer takes the lean authority, and it hovers on, level and armed."""
    rig = Rig("ahead", 0).airborne()
    data, width = rig.data, rig.af.sc.room.width
    data.qpos[0], data.qpos[1] = width - FRAME.radius_m - 0.3, rig.af.sc.room.depth / 2.0
    data.qvel[:] = 0.0
    data.qvel[0] = 0.4
    rig.run(3.0, yaw=CH["yaw"].maximum)
    state = rig.af.state
    assert state.wall_hits >= 1 and state.crashes == 0 and rig.af.fc.armed
    sensors = rig.af.sensors()
    assert abs(sensors.roll) < math.radians(10) and abs(sensors.pitch) < math.radians(10)
    assert state.z > 0.8


def test_a_steady_torque_is_worked_off_by_the_rate_integrators() -> None:
    """A steady roll torque (a touch's friction, an off-centre load) leaves a P-only attitude loop leaning; the rate
    loops' integrators (ATC_RAT_RLL_I, capped at ATC_RAT_RLL_IMAX) bring the airframe back to level."""
    rig = Rig("ahead", 0).airborne()
    push = 0.25  # N m about the body's x axis, held
    rig.data.xfrc_applied[rig.af.body, 3] = push
    rig.run(0.3)
    early = abs(rig.af.sensors().roll)
    rig.run(3.0)
    late = abs(rig.af.sensors().roll)
    assert early > math.radians(2.0)  # the torque does lean it at first
    assert late < 0.25 * early and late < math.radians(1.0)
    assert rig.af.state.crashes == 0 and rig.af.fc.armed
