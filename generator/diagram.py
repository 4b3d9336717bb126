"""The wiring diagram of the docs (generated/docs/wiring.svg), laid out from the spec's `wiring:` section: one
row per Arduino pin, a wire to what it connects to. The template only prints these rows."""

from __future__ import annotations

from .model import Spec
from .records import record

COLOURS = {"rc": "#0550ae", "servo": "#8250df", "laser": "#cf222e", "power": "#1b1f24", "usb": "#116329"}
ROW_PX = 34
TOP_PX = 70


@record
class Wire:
    y: int
    pin: str  # "D2", "GND", "USB"
    signal: str
    to: str  # the device and input it connects to
    group: str  # "rc", "servo", "laser", "power", "usb": the device box it ends in

    @property
    def colour(self) -> str:
        return COLOURS[self.group]


def wires(spec: Spec) -> tuple[Wire, ...]:
    w = spec.wiring
    rows = [(f"D{p.pin}", f"{p.name} (RC, 50 Hz PWM)", f"flight controller RC input {p.rc_input}", "rc")
            for p in w.rc_inputs]
    rows += [(f"D{p.pin}", f"{p.name} servo signal", f"{p.name} servo signal wire", "servo") for p in w.servos]
    rows += [(f"D{w.laser.pin}", "laser (on/off)", "laser driver input (never the laser itself)", "laser"),
             ("GND", "common ground", "flight controller, servos and laser supply ground", "power"),
             ("USB", f"serial {spec.baud} 8N1", "Raspberry Pi (/dev/ttyACM0)", "usb")]
    return tuple(Wire(TOP_PX + i * ROW_PX, pin, signal, to, group) for i, (pin, signal, to, group) in enumerate(rows))


def height(spec: Spec) -> int:
    return TOP_PX + len(wires(spec)) * ROW_PX + 30
