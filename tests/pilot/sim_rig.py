"""The airframe alone in a scenario's MuJoCo room, driven by RC pulses (the simulator's tests)."""

from __future__ import annotations

import dataclasses

import drone_protocol as dp

from pilot.sim import mj, rc
from pilot.sim.physics import Airframe
from pilot.sim.randomise import IDEAL, Effects
from pilot.sim.room import make_scenario
from pilot.sim.scene import build

CH = dp.CHANNELS
PARAMS = rc.load()
ALT_HOLD = dp.MODE_ALT_HOLD_US
STABILIZE = dp.MODE_STABILIZE_US
MEDIANS = {n: float(CH[dp.ChannelName(n)].median) for n in ("roll", "pitch", "throttle", "yaw")}


class Rig:
    """The airframe alone in a scenario's room, driven by pulses."""

    def __init__(self, name: str = "ahead", seed: int = 0, effects: Effects = IDEAL) -> None:
        mujoco = mj.module()
        sc = dataclasses.replace(make_scenario(name, seed, ideal=True), effects=effects)
        params = PARAMS.varied(effects)
        built = build(sc, params.airframe, 64, 48, 45.0)
        self.model = mujoco.MjModel.from_xml_string(built.xml, built.assets)
        self.data = mujoco.MjData(self.model)
        self.af = Airframe(sc, params, self.model, self.data)

    def run(self, seconds: float, mode: float = ALT_HOLD, **sticks: float) -> None:
        p = {**MEDIANS, **sticks}
        for _ in range(round(seconds / 0.002)):
            self.af.step((p["roll"], p["pitch"], p["throttle"], p["yaw"], mode), 0.002)

    def airborne(self) -> Rig:
        self.run(2.2, STABILIZE, throttle=CH["throttle"].minimum, yaw=CH["yaw"].maximum)
        assert self.af.fc.armed
        self.run(3.0, throttle=CH["throttle"].high)
        self.run(2.0)
        assert self.af.state.z > 1.0 and not self.af.fc.landed
        return self
