"""The airframe in MuJoCo, flown by the emulated flight controller from the virtual drone's RC pulses.

Each 2 ms step: the flight controller reads the pulses and the airframe's attitude, rates and height
(``arducopter.py``), an attitude and rate loop (with integrators on roll and pitch) turns its demand into torques,
the mixer (``mixer.py``) into four motor thrusts (MuJoCo's actuators add the motor lag and the reaction torques),
drag against the moving air (steady wind plus seeded gusts) is applied, and MuJoCo integrates. Contacts are
scored: a wall, furniture or target touch is a wall hit; touching the floor faster than the airframe's crash
speed, or tipping over, is a crash.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from . import mj
from .arducopter import FlightController, Sensors
from .estimator import Estimator
from .mixer import Mixer
from .rc import SimParams
from .scenario import Scenario
from .scene import HIDDEN_GROUP

FloatArray = npt.NDArray[np.float64]
HIT_GAP_S = 0.5
BODY_HALF_HEIGHT = 0.05  # the airframe's collision box: its centre rests this high on the floor


@dataclass
class AirframeState:
    """What the world reports and scores (world frame; heading counter-clockwise from +x)."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    heading: float = 0.0
    armed: bool = False  # the flight controller's arming
    wall_hits: int = 0
    crashes: int = 0
    touching: bool = False
    hit_what: list[str] = field(default_factory=list)  # what each wall hit touched, and when


def _euler(w: float, x: float, y: float, z: float) -> tuple[float, float, float]:
    """Roll, pitch and yaw (ZYX, MuJoCo's FLU frame) of a unit quaternion."""
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return roll, pitch, yaw


class Airframe:
    def __init__(self, scenario: Scenario, params: SimParams, model: mj.Model, data: mj.Data) -> None:
        mujoco = mj.module()
        self.sc, self.p, self.model, self.data = scenario, params, model, data
        frame = params.airframe
        self.frame = frame
        self.fc = FlightController(params, frame.mass_kg, 4.0 * frame.motor_max_n)
        self.estimator = Estimator(scenario.effects, scenario.seed, frame.mass_kg, frame.drag_linear,
                                   frame.drag_quadratic)
        self.state = AirframeState(x=scenario.start[0], y=scenario.start[1], heading=scenario.start[2])
        self._kp_roll, self._kp_pitch = params["ATC_ANG_RLL_P"], params["ATC_ANG_PIT_P"]
        # the rate loops' integrators (ArduCopter's ATC_RAT_*_I over _P, per second, capped at ATC_RAT_*_IMAX of
        # full authority): a steady torque (a wall touch's friction, an off-centre load) is worked off
        self._ki = frame.rate_gain * params["ATC_RAT_RLL_I"] / params["ATC_RAT_RLL_P"]
        full = 2.0 * frame.motor_max_n * frame.arm_m / math.sqrt(2.0)  # torque of two motors' full thrust
        self._i_max = params["ATC_RAT_RLL_IMAX"] * full
        self._i_x = self._i_y = 0.0
        self._mixer = Mixer(frame.arm_m, frame.yaw_moment_m, params["MOT_SPIN_MIN"] * frame.motor_max_n,
                            frame.motor_max_n, params["MOT_YAW_HEADROOM"])
        self._moving = scenario.target_motion[0] != 0.0 or scenario.target_motion[1] != 0.0
        self._hides = bool(scenario.hidden)
        self.body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "drone")
        target = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "target")
        self.target_body = model.body_mocapid[target]
        self.target_home = np.array(model.body_pos[target])
        self.floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "floor")
        self.airframe_geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "airframe")
        self.target_geoms = [i for i in range(model.ngeom)
                             if (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, i) or "").startswith("target_")]
        self._target_contype = model.geom_contype[self.target_geoms].copy()  # restored when it shows again
        self._hidden = False
        self._on_floor = True
        self._tipped = False
        self._last_touch_t = -1.0
        self._gust = np.zeros(2)
        self._rng = np.random.default_rng([scenario.seed, 0x6057])
        self.t = 0.0
        mujoco.mj_forward(model, data)

    # -- sensing ------------------------------------------------------------------------------------------
    def sensors(self, dt: float = 0.0) -> Sensors:
        """What the flight controller senses (``dt``: the step the height estimate advances by; 0: the truth)."""
        roll, pitch, yaw = _euler(*self.data.qpos[3:7].tolist())
        v = self.data.qvel.tolist()  # angular part: body frame (FLU) for a free joint
        height = float(self.data.qpos[2]) - BODY_HALF_HEIGHT
        if dt > 0.0:  # ArduCopter's senses: roll right-down (FLU +x), pitch nose-up (FLU -y), yaw clockwise (FLU -z)
            roll, pitch_up = self.estimator.attitude(roll, -pitch)
            return Sensors(roll, pitch_up, -yaw, v[3], -v[4], -v[5],
                           self.estimator.height(height, self.fc.armed, dt), v[2])
        return Sensors(roll, -pitch, -yaw, v[3], -v[4], -v[5], height, v[2])

    # -- one step -----------------------------------------------------------------------------------------
    def step(self, pulses: tuple[float, float, float, float, float], dt: float) -> None:
        mujoco = mj.module()
        s = self.sensors(dt)
        demand = self.fc.step(pulses, s, dt)
        frame = self.frame
        ctrl = self.data.ctrl
        if not demand.motors_on:
            ctrl[:] = 0.0
        else:
            # angle loop (ArduCopter's senses) -> body rates (FLU) -> angular accelerations -> torques
            rates = self.data.qvel
            gain = frame.rate_gain
            ix, iy, iz = frame.inertia
            err_x = self._kp_roll * (demand.roll - s.roll) - rates[3]
            err_y = -self._kp_pitch * (demand.pitch - s.pitch) - rates[4]
            if self.fc.landed:
                self._i_x = self._i_y = 0.0  # ArduCopter resets its rate integrators on the ground
            else:
                self._i_x = min(max(self._i_x + ix * self._ki * err_x * dt, -self._i_max), self._i_max)
                self._i_y = min(max(self._i_y + iy * self._ki * err_y * dt, -self._i_max), self._i_max)
            wrench = (demand.collective * 4.0 * frame.motor_max_n,
                      ix * gain * err_x + self._i_x,
                      iy * gain * err_y + self._i_y,
                      iz * gain * (-demand.yaw_rate - rates[5]))
            ctrl[:] = self._mixer.thrusts(*wrench)
        self._air()
        if self._moving or self._hides:
            self._target()
        mujoco.mj_step(self.model, self.data)
        self.t += dt
        if self.data.ncon:
            self._score_contacts()
        else:  # airborne: the next floor contact is a touchdown, judged on its speed
            self.state.touching = False
            self._on_floor = False
        self._update_state()

    def _air(self) -> None:
        """Drag against the moving air: steady wind plus gusts (an Ornstein-Uhlenbeck process, 2 s memory)."""
        sc, v = self.sc, self.data.qvel
        wx, wy = sc.wind
        if sc.gusts > 0.0:
            theta, dt = 0.5, 0.002
            g = self._gust
            g += -theta * g * dt + sc.gusts * math.sqrt(2.0 * theta * dt) * self._rng.normal(size=2)
            wx, wy = wx + float(g[0]), wy + float(g[1])
        if self.data.qpos[2] <= 0.08:
            wx = wy = 0.0  # on the ground the air does not push it
        rx, ry, rz = v[0] - wx, v[1] - wy, v[2]
        speed = math.sqrt(rx * rx + ry * ry + rz * rz)
        k = -(self.frame.drag_linear + self.frame.drag_quadratic * speed)
        f = self.data.xfrc_applied[self.body]
        f[0], f[1], f[2] = k * rx, k * ry, k * rz

    def _target(self) -> None:
        dx, dy = self.sc.target_offset(self.t)
        self.data.mocap_pos[self.target_body] = self.target_home + np.array([dx, dy, 0.0])
        hidden = not self.sc.target_visible(self.t)
        if hidden != self._hidden:
            self._hidden = hidden
            self.model.geom_group[self.target_geoms] = HIDDEN_GROUP if hidden else 0
            self.model.geom_contype[self.target_geoms] = 0 if hidden else self._target_contype

    def _score_contacts(self) -> None:
        d, st = self.data, self.state
        touching = on_floor = touched_down = False
        for i in range(d.ncon):
            c = d.contact[i]
            pair = (int(c.geom1), int(c.geom2))
            on_floor = on_floor or self.floor in pair
            if self.airframe_geom not in pair:
                continue
            other = pair[0] if pair[1] == self.airframe_geom else pair[1]
            if other == self.floor:
                # judged once per touchdown (a landing makes several contacts in the same step)
                if -float(d.qvel[2]) > self.frame.crash_speed and not self._on_floor and not touched_down:
                    st.crashes += 1
                touched_down = True
                continue
            # one hit per touch: a bouncing contact (on and off within HIT_GAP_S) is the same touch
            if not st.touching and not touching and self.t - self._last_touch_t > HIT_GAP_S:
                name = mj.module().mj_id2name(self.model, mj.module().mjtObj.mjOBJ_GEOM, other) or "?"
                st.hit_what.append(f"{name} at {self.t:.1f} s")
                st.wall_hits += 1
            touching = True
        self._on_floor = on_floor
        if touching:
            self._last_touch_t = self.t
        st.touching = touching

    def _update_state(self) -> None:
        st, q = self.state, self.data.qpos.tolist()
        st.x, st.y, st.z = q[0], q[1], max(0.0, q[2] - BODY_HALF_HEIGHT)
        w, x, y, z = q[3:7]
        st.heading = _euler(w, x, y, z)[2]
        st.armed = self.fc.armed
        up = 1.0 - 2.0 * (x * x + y * y)  # the body's z axis against the world's
        if up < 0.3 and not self._tipped:
            self._tipped = True
            st.crashes += 1
