"""The MuJoCo simulator: ArduCopter's stick mappings (one step input each, against the documented figure),
arming, failsafe, the scenes and the camera/laser mount."""

from __future__ import annotations

import math

import drone_protocol as dp
import numpy as np
import pytest
from sim_rig import ALT_HOLD, CH, MEDIANS, PARAMS, STABILIZE, Rig

from pilot.sim import mj
from pilot.sim.arducopter import FlightController, Mode, Sensors, desired_climb_rate, desired_lean
from pilot.sim.camera import CameraModel, rolling_shutter
from pilot.sim.room import SCENARIOS, make_scenario
from pilot.sim.scene import HIDDEN_GROUP
from pilot.sim.still import StillView
from pilot.vision.detect import HsvBlobDetector


def test_parameters_come_from_the_generated_file() -> None:
    assert PARAMS.source.endswith("drone.parm")
    assert PARAMS.sticks[dp.ChannelName.PITCH].reversed  # the spec's flight_controller.reversed
    assert PARAMS["THR_DZ"] < 100  # the spec's dead band, not ArduCopter's default
    assert PARAMS.mode_number(ALT_HOLD) == 2 and PARAMS.mode_number(STABILIZE) == 0


def test_mapping_lean_angle_is_linear_to_angle_max_with_a_circular_limit() -> None:
    full = desired_lean(PARAMS, 4500.0, 0.0)
    assert math.degrees(full[0]) == pytest.approx(PARAMS["ANGLE_MAX"] / 100.0)
    both = desired_lean(PARAMS, 4500.0, 4500.0)
    assert math.degrees(math.hypot(*both)) == pytest.approx(PARAMS["ANGLE_MAX"] / 100.0)
    rig = Rig().airborne()
    rig.run(1.0, roll=CH["roll"].maximum)  # a step: the airframe reaches ANGLE_MAX within a few time constants
    assert math.degrees(rig.af.sensors().roll) == pytest.approx(PARAMS["ANGLE_MAX"] / 100.0, abs=1.5)


def test_mapping_forward_leans_nose_down_and_a_released_stick_coasts() -> None:
    rig = Rig().airborne()
    h = rig.af.state.heading
    x0, y0 = rig.af.state.x, rig.af.state.y
    rig.run(1.5, pitch=CH["pitch"].high)  # move forward (Table 3): nose down, through RC2_REVERSED
    assert rig.af.sensors().pitch < math.radians(-3)
    rig.run(0.6)  # released: levels within ATC_INPUT_TC's few time constants ...
    assert abs(math.degrees(rig.af.sensors().pitch)) < 1.0
    v = np.asarray(rig.data.qvel[0:2])
    along = float(v @ [math.cos(h), math.sin(h)])
    assert along > 0.3  # ... and coasts on: no position hold
    moved = (rig.af.state.x - x0) * math.cos(h) + (rig.af.state.y - y0) * math.sin(h)
    assert moved > 0.3


def test_mapping_yaw_stick_is_a_rate_up_to_pilot_y_rate() -> None:
    rig = Rig().airborne()
    h0 = rig.af.state.heading
    rig.run(1.0, yaw=CH["yaw"].maximum)
    rig.run(1.0, yaw=CH["yaw"].maximum)
    turned = (h0 - rig.af.state.heading) % (2 * math.pi)  # right: clockwise, the heading decreases
    rate, accel = PARAMS["PILOT_Y_RATE"], PARAMS["ATC_ACCEL_Y_MAX"] / 100.0
    # the rate target ramps up at ATC_ACCEL_Y_MAX, and the airframe follows it through its rate loop
    lag = rate / accel / 2.0 + 1.0 / PARAMS.airframe.rate_gain
    assert math.degrees(turned) == pytest.approx(rate * (2.0 - lag), rel=0.03)


def test_mapping_throttle_is_a_climb_rate_with_a_dead_band() -> None:
    mid = MEDIANS["throttle"]
    assert desired_climb_rate(PARAMS, PARAMS.sticks[dp.ChannelName.THROTTLE].range(mid)) == 0.0
    assert desired_climb_rate(PARAMS, 1000.0) == pytest.approx(PARAMS["PILOT_SPEED_UP"] / 100.0)
    rig = Rig().airborne()
    z0 = rig.af.state.z
    rig.run(2.0)  # centred: the altitude is held
    assert rig.af.state.z == pytest.approx(z0, abs=0.05)
    want = desired_climb_rate(PARAMS, PARAMS.sticks[dp.ChannelName.THROTTLE].range(CH["throttle"].high))
    assert want > 0.3  # the spec's speed step is outside the dead band
    rig.run(1.0, throttle=CH["throttle"].high)
    z1 = rig.af.state.z
    rig.run(1.0, throttle=CH["throttle"].high)
    assert rig.af.state.z - z1 == pytest.approx(want, rel=0.15)


def test_arming_needs_the_sticks_held_on_the_ground_and_the_failsafe_lands() -> None:
    rig = Rig()
    rig.run(1.0, STABILIZE, throttle=CH["throttle"].minimum, yaw=CH["yaw"].maximum)
    rig.run(0.1, STABILIZE, throttle=CH["throttle"].minimum)  # released too early
    rig.run(1.5, STABILIZE, throttle=CH["throttle"].minimum, yaw=CH["yaw"].maximum)
    assert not rig.af.fc.armed
    rig.airborne()
    # disarm sticks in the air: refused (throttle at zero in AltHold descends at PILOT_SPEED_DN, 2.5 m/s, so
    # this drone touches down hard: the failsafe below flies a fresh one)
    rig.run(3.0, throttle=CH["throttle"].minimum, yaw=CH["yaw"].minimum)
    assert rig.af.fc.armed
    rig = Rig().airborne()
    rig.run(8.0, throttle=dp.FAILSAFE_THROTTLE_US)  # the radio failsafe: Land, then disarm on the ground
    assert rig.af.state.z < 0.02 and not rig.af.fc.armed
    assert rig.af.state.crashes == 0 and rig.af.state.wall_hits == 0


@pytest.mark.parametrize("name", SCENARIOS)
def test_scenarios_are_deterministic_and_inside_the_room(name: str) -> None:
    for seed in range(10):
        a, b = make_scenario(name, seed), make_scenario(name, seed)
        assert a == b
        tx, ty, tz = a.target.position
        assert a.room.inside(tx, ty, 1.0) and 0.0 < tz < a.room.height
        assert a.room.inside(a.start[0], a.start[1], 1.0)
        for prop in a.props:
            if prop.shape != "poster":
                assert a.room.inside(prop.position[0], prop.position[1], 0.2)
    assert make_scenario(name, 1) != make_scenario(name, 2)
    assert make_scenario("red_distractors", 1).distractors


def test_render_is_deterministic_and_the_target_is_where_it_projects() -> None:
    sc = make_scenario("distractor", 4)
    x, y, _ = sc.start
    tx, ty, tz = sc.target.position
    heading = math.atan2(ty - y, tx - x) + math.radians(8)
    frames = []
    for _ in range(2):
        view = StillView(sc, CameraModel(320, 240))
        view.place(x, y, tz, heading)
        frames.append(view.render(1.0))
        projected = view.project(sc.target.position)
        view.close()
    assert np.array_equal(frames[0], frames[1])
    assert projected is not None
    d = HsvBlobDetector().detect(frames[0])
    assert d.found
    assert abs(d.cx - projected[0]) <= 3 and abs(d.cy - projected[1]) <= 3


def test_tilt_moves_the_view() -> None:
    sc = make_scenario("hidden", 0, noise=False)
    view = StillView(sc, CameraModel(320, 240))
    x, y, _ = sc.start
    tx, ty, tz = sc.target.position
    heading = math.atan2(ty - y, tx - x)
    view.place(x, y, tz, heading)
    level = view.project(sc.target.position)
    tilt0 = dp.SERVOS[dp.ServoName.TILT].default
    view.place(x, y, tz, heading, tilt=tilt0 + 10)  # looking up: the target drops in the frame
    up = view.project(sc.target.position)
    assert level is not None and up is not None and up[1] > level[1] + 30
    d = HsvBlobDetector().detect(view.render(0.0))
    assert d.found and abs(d.cy - up[1]) <= 4
    view.close()


def test_a_hidden_target_leaves_the_view_and_the_laser_path() -> None:
    rig = Rig("hidden", 0)
    begin = rig.af.sc.hidden[0].start
    rig.run(begin - 0.1)
    assert all(rig.model.geom_group[g] == 0 for g in rig.af.target_geoms)
    rig.run(0.2)
    assert rig.af.target_geoms and all(rig.model.geom_group[g] == HIDDEN_GROUP for g in rig.af.target_geoms)


def test_the_flying_pilot_never_imports_the_simulator() -> None:
    """The command line (which names the scenarios) loads neither MuJoCo nor the simulator's photographs."""
    import subprocess
    import sys

    code = ("import sys, pilot.app.cli, pilot.app.runner, pilot.link.serial_link, pilot.control.controller; "
            "bad = [m for m in sys.modules if m.split('.')[0] in ('mujoco', 'skimage') "
            "or m in ('pilot.sim.world', 'pilot.sim.physics', 'pilot.sim.camera', 'pilot.sim.scene')]; "
            "print(bad); sys.exit(1 if bad else 0)")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stdout + run.stderr


def test_the_crash_check_disarms_an_airframe_stuck_off_its_attitude() -> None:
    """Wedged against a wall at 60° of roll, in the air: ArduCopter's crash check disarms after 2 s."""
    fc = FlightController(PARAMS, PARAMS.airframe.mass_kg, 4 * PARAMS.airframe.motor_max_n)
    fc.armed, fc.landed, fc.mode = True, False, Mode.ALT_HOLD
    fc._alt_target = 1.0  # holding the 1 m it flies at
    pulses = (MEDIANS["roll"], MEDIANS["pitch"], MEDIANS["throttle"], MEDIANS["yaw"], float(ALT_HOLD))
    stuck = Sensors(math.radians(60), 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    level = Sensors(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    for _ in range(round(1.5 / 0.002)):
        assert fc.step(pulses, stuck, 0.002).motors_on
    fc.step(pulses, level, 0.002)  # back on its attitude: the count starts again
    for _ in range(round(1.9 / 0.002)):
        fc.step(pulses, stuck, 0.002)
    assert fc.armed
    for _ in range(round(0.2 / 0.002)):
        demand = fc.step(pulses, stuck, 0.002)
    assert not fc.armed and not demand.motors_on


def test_a_rolling_shutter_shears_a_moving_image_by_each_row_s_delay() -> None:
    img = np.zeros((240, 320, 3), np.uint8)
    img[:, 160] = 255  # a vertical line; the image moves right at 600 px/s, rows read over 30 ms
    out = rolling_shutter(img, np.array([600.0, 0.0]), 0.03)
    for row in (0, 120, 239):
        delay = ((row + 0.5) / 240 - 0.5) * 0.03
        assert abs(int(np.argmax(out[row, :, 0])) - (160 + 600.0 * delay)) <= 1
    assert rolling_shutter(img, np.array([10.0, 0.0]), 0.03) is img  # under half a pixel: untouched


def test_the_rolling_shutter_option_changes_only_frames_taken_while_turning() -> None:
    sc = make_scenario("ahead", 2, noise=False)
    x, y, heading = sc.start
    frames: dict[float, list[np.ndarray]] = {}
    for readout in (0.0, 0.03):
        view = StillView(sc, CameraModel(320, 240, readout_s=readout))
        shots = []
        for k, turn in enumerate((0.0, 0.0, 0.05)):  # still, still, then 2.9° in 50 ms: 57°/s
            view.place(x, y, 1.2, heading + turn)
            shots.append(view.render(0.05 * k))
        view.close()
        frames[readout] = shots
    assert np.array_equal(frames[0.0][1], frames[0.03][1])  # not turning: a global and a rolling shutter agree
    assert not np.array_equal(frames[0.0][2], frames[0.03][2])


def test_the_firmware_landing_routine_disarms_the_flight_controller_from_under_the_ceiling() -> None:
    """The landing routine (``il0000``): AltHold with the throttle at its low speed for LANDING_MS, then the disarm
    sticks for ARMING_HOLD_MS. From 2.6 m (the room is 3 m high) the flight controller must be down, past its land
    detector, and disarmed by the end: a 6 s landing was too short for 2.4 m, and a hold of exactly 2 s left the
    20th tick of ArduCopter's 10 Hz check to its phase (here it fell after the hold)."""
    rig = Rig().airborne()
    while rig.af.state.z < 2.6:
        rig.run(0.1, throttle=CH["throttle"].high)
    rig.run(1.0)  # settled at the top
    rig.run(dp.LANDING_MS / 1000.0, throttle=CH["throttle"].low)
    assert rig.af.state.z < 0.02
    rig.run(dp.ARMING_HOLD_MS / 1000.0, throttle=CH["throttle"].minimum, yaw=CH["yaw"].minimum)
    assert not rig.af.fc.armed


def _touches(rig: Rig, x: float, y: float, z: float) -> set[str]:
    """What the airframe, put at (x, y, z), is in contact with."""
    mujoco = mj.module()
    rig.data.qpos[:3] = (x, y, z)
    mujoco.mj_forward(rig.model, rig.data)
    names = set()
    for c in rig.data.contact[: rig.data.ncon]:
        pair = (int(c.geom1), int(c.geom2))
        if rig.af.airframe_geom in pair:
            other = pair[0] if pair[1] == rig.af.airframe_geom else pair[1]
            names.add(mujoco.mj_id2name(rig.model, mujoco.mjtObj.mjOBJ_GEOM, other))
    return names


def test_the_marker_plate_and_the_pictures_are_touched_only_where_they_are() -> None:
    """MuJoCo collides with a plane as an infinite half-space: the marker's plane once made a wall of the whole
    room behind the target. Beside the plate along its plane, and behind it, nothing of the target (the room's
    everyday things may stand there); at the plate, its backing board."""
    rig = Rig("ahead", 0)
    sc = rig.af.sc
    assert sc.marker is not None
    px, py, pz = sc.marker.centre
    along = (-math.sin(sc.marker.facing), math.cos(sc.marker.facing))  # in the plate's plane, horizontal
    normal = (math.cos(sc.marker.facing), math.sin(sc.marker.facing))
    beside = [(px + 1.5 * k * along[0], py + 1.5 * k * along[1]) for k in (-1.0, 1.0)]  # 1.5 m off, in its plane
    behind = (px - 1.0 * normal[0], py - 1.0 * normal[1])
    for x, y in (*beside, behind):
        assert sc.room.inside(x, y, 0.4)  # clear of the walls, so that any contact is the plate's
        assert {n for n in _touches(rig, x, y, pz) if n.startswith("target")} == set()
    # the airframe's front edge reaching the board
    reach = PARAMS.airframe.radius_m + 0.02
    assert "target_backing" in _touches(rig, px + reach * normal[0], py + reach * normal[1], pz)


def test_a_camera_against_a_wall_sees_the_wall_not_the_void_behind_it() -> None:
    """The airframe's nose touching the west wall (x = 0) puts the camera 2 cm from it: inside MuJoCo's default
    near plane (11 cm here), the wall was clipped away and the frame black, which the pilot reads as a dead
    camera."""
    sc = make_scenario("ahead", 0)
    view = StillView(sc, CameraModel(320, 240))
    view.place(PARAMS.airframe.radius_m + 0.005, sc.room.depth / 2, 1.2, math.pi)  # facing the wall, nose on it
    frame = view.render(1.0)
    view.close()
    assert float(frame.mean()) > 40.0  # the lit wall (a black frame: under 12)
