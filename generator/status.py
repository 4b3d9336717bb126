"""Validate the spec's `status` section: the state and laser codes every reply reports."""

from __future__ import annotations

from .errors import SpecError
from .model import Status, StatusState
from .names import identifier_problem
from .reader import Reader, is_letter_code, unique_code

# The firmware's state machine reports each of these; a spec must give every one a code.
STATES = ("disarmed", "arming", "armed", "hold_altitude", "moving", "landing", "disarming", "self_test", "failsafe")


def read_status(top: Reader, errors: list[SpecError]) -> Status:
    section = top.section("status")
    states: list[StatusState] = []
    codes: dict[str, str] = {}
    for name, node in section.entries("states"):
        r = Reader(node, f"status.states.{name}", errors)
        problem = identifier_problem(name)
        if problem:
            errors.append(SpecError(node.key_location, r.path, problem, "names become Python and C++ identifiers"))
            continue
        if not r.ok:
            continue
        code = unique_code(r, "state", name, codes)
        armed = r.get("armed", bool)
        description = r.text("description")
        r.finish()
        if code is not None:
            states.append(StatusState(name, code, bool(armed), description))
    states_node = section.node.children.get("states") if section.ok else None
    if states_node is not None and isinstance(states_node.value, dict):
        for name in STATES:
            if name not in states_node.children:
                errors.append(SpecError(states_node.location, f"status.states.{name}", f"missing state '{name}'",
                                        "the firmware reports every state of its state machine"))
    laser = Reader(section.child("laser") or section.node, "status.laser", errors)
    off, on = laser.text("off"), laser.text("on")
    laser.finish()
    for key, code in (("off", off), ("on", on)):
        if laser.ok and key in laser.node.children and not is_letter_code(code):
            laser.error(laser.node.children[key], f"laser code {code!r} is not one letter or digit",
                        path=laser.sub(key))
    if off and off == on:
        laser.error(laser.node.children["on"], f"laser codes for on and off are both '{on}'", path=laser.sub("on"))
    section.finish()
    order = {name: i for i, name in enumerate(STATES)}
    states.sort(key=lambda s: order.get(s.name, len(STATES)))
    return Status(tuple(states), off, on)
