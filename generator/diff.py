"""What changed between two versions of the protocol, and which changes break a peer built from the old one.

Both versions are reduced to a contract: the facts a peer relies on (frame layout, link, command codes and
their ranges and meaning, error and reply codes, timing, and how the drone flies: the speed step and the flight
controller's parameters, any change of which needs them loaded again) plus the texts. The generator writes the
contract of what it generated to generated/contract.json, so the next generation (and `--check`) can tell a
breaking edit whose protocol.version did not rise, without git or the old spec file.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from .ardupilot import parameter_files
from .model import Spec
from .records import record

Contract = dict[str, Any]


def contract(spec: Spec) -> Contract:
    """The facts of `spec` a peer relies on, as plain JSON values (keys are stable across spec formats)."""
    return {
        "name": spec.name,
        "version": spec.version,
        "frame": {"length": spec.frame_length, "encoding": "ascii", "integrity": spec.integrity,
                  "wire_length": spec.wire_length, "inter_byte_timeout_ms": spec.inter_byte_timeout_ms},
        "link": {"baud": spec.baud, "data_bits": spec.data_bits, "parity": spec.parity, "stop_bits": spec.stop_bits,
                 "ready_timeout_ms": spec.ready_timeout_ms},
        "timing": {"command_timeout_ms": spec.command_timeout_ms, "failsafe_timeout_ms": spec.failsafe_timeout_ms,
                   "failsafe_throttle_us": spec.failsafe_throttle_us, "arming_hold_ms": spec.arming_hold_ms,
                   "landing_ms": spec.landing_ms},
        "commands": {
            cmd.category.code + cmd.direction.code: {
                "name": cmd.direction.command, "min": cmd.direction.minimum, "max": cmd.direction.maximum,
                "default": cmd.direction.default, "target": cmd.direction.target, "sense": cmd.direction.sense,
                "routine": cmd.direction.routine, "unit": cmd.direction.field.unit,
                "description": cmd.direction.description,
            } for cmd in spec.commands
        },
        "errors": {e.name: {"code": e.code, "description": e.description} for e in spec.errors},
        "replies": {r.name: {"prefix": r.prefix, "description": r.description} for r in spec.replies},
        # every accepted/rejected/failsafe line ends with separator, state code, laser code
        "status": {"separator": spec.status.separator, "laser_off": spec.status.laser_off,
                   "laser_on": spec.status.laser_on},
        "states": {st.name: {"code": st.code, "armed": st.armed, "description": st.description}
                   for st in spec.status.states},
        "texts": {"title": spec.title, "description": spec.description},
        # how the drone flies: the speed step (the firmware's default speeds and its landing descent) and the
        # parameters the flight controller must be loaded with (generated/ardupilot/<line>/), per ArduCopter line
        "flight": {"step_us": spec.speed_step_us},
        "flight_controller": {f"{lp.line.folder}/{p.name}": p.value
                              for lp in parameter_files(spec) for p in lp.params},
    }


# What each entry of a contract's tables holds, as `contract` writes it: the keys `diff` reads, and their types.
_ENTRIES: dict[str, dict[str, tuple[type, ...]]] = {
    "commands": {"name": (str,), "min": (int,), "max": (int,), "default": (int, type(None)), "target": (str,),
                 "sense": (int,), "routine": (str, type(None)), "unit": (str,), "description": (str,)},
    "errors": {}, "replies": {}, "states": {},  # read with .get(): any mapping will do
}


def contract_problem(found: object) -> str | None:
    """Why `found` is not a contract as `contract` writes it (a hand edit, a bad merge), or None. A section or table
    may be missing: a contract written before it existed."""
    if not isinstance(found, dict):
        return "it is not a mapping"
    if not isinstance(found.get("name"), str) or type(found.get("version")) is not int:
        return "its name or its integer version is missing"
    for section in ("frame", "link", "status", "timing", "texts", "flight", "flight_controller", *_ENTRIES):
        if not isinstance(found.get(section, {}), dict):
            return f"{section} is not a mapping"
    for table, keys in _ENTRIES.items():
        for code, entry in found.get(table, {}).items():
            if not isinstance(entry, dict):
                return f"{table}.{code} is not a mapping"
            for key, kinds in keys.items():
                value = entry.get(key, ...)
                if not isinstance(value, kinds) or (isinstance(value, bool) and bool not in kinds):
                    return f"{table}.{code}.{key} is missing or not {' or '.join(k.__name__ for k in kinds)}"
    return None


@record
class Change:
    breaking: bool
    what: str

    def __str__(self) -> str:
        return f"{'BREAK' if self.breaking else 'ok':6}{self.what}"


def diff(old: Contract, new: Contract) -> list[Change]:
    """Every difference between two contracts, breaking ones first, each in a sentence."""
    changes: list[Change] = []
    if old.get("name") != new.get("name"):
        changes.append(Change(True, f"protocol name {old.get('name')} -> {new.get('name')} (the ready line)"))
    _sections(old, new, changes)
    _entries(old, new, "commands", changes, _command_change)
    _entries(old, new, "errors", changes, _keyed_change("error", "code"))
    _entries(old, new, "replies", changes, _keyed_change("reply", "prefix"))
    _entries(old, new, "states", changes, _keyed_change("state", "code", "armed"))
    _flight_controller(old, new, changes)
    old_names = {c["name"]: code for code, c in old.get("commands", {}).items()}
    for code, cmd in new.get("commands", {}).items():
        was = old.get("commands", {}).get(code)
        if was is not None and was["name"] != cmd["name"] and old_names.get(cmd["name"], code) != code:
            changes.append(Change(True, f"command {code}: now {cmd['name']}, which was {old_names[cmd['name']]} "
                                        "(a code reused with another meaning)"))
    return sorted(changes, key=lambda c: not c.breaking)


# frame and link: any change breaks a peer, but for these (timeout rising: a slow peer still fits).
_TOLERANT = {("frame", "inter_byte_timeout_ms"): "rise", ("link", "ready_timeout_ms"): "any",
             ("timing", "command_timeout_ms"): "any", ("timing", "failsafe_timeout_ms"): "rise",
             ("timing", "failsafe_throttle_us"): "any", ("timing", "arming_hold_ms"): "any",
             ("timing", "landing_ms"): "any"}


def _sections(old: Contract, new: Contract, changes: list[Change]) -> None:
    for section in ("frame", "link", "status", "timing", "texts", "flight"):
        if section not in old or section not in new:
            continue  # a contract written before the section existed: nothing to compare
        before, after = old[section], new[section]
        for key in sorted(before):  # a key the old contract does not record is not compared
            a, b = before[key], after.get(key)
            if a == b:
                continue
            rule = "any" if section in ("texts", "flight") else _TOLERANT.get((section, key), "never")
            rose = isinstance(a, int) and isinstance(b, int) and b > a
            breaking = rule == "never" or (rule == "rise" and not rose)
            note = " (how the drone flies: the default speeds and the landing descent)" if section == "flight" else ""
            changes.append(Change(breaking, f"{section}.{key}: {a!r} -> {b!r}{note}"))


def _flight_controller(old: Contract, new: Contract, changes: list[Change]) -> None:
    """Any change to the flight controller's parameters breaks a drone loaded with the old ones: it flies
    otherwise (a dead band, a reversed stick, a range) until its line's generated/ardupilot/<line>/ file is loaded
    again. Keys are `<line folder>/<parameter>`."""
    if "flight_controller" not in old or "flight_controller" not in new:
        return  # a contract written before the section existed
    before, after = old["flight_controller"], new["flight_controller"]
    reload = "re-load the parameter file in generated/ardupilot/ into the flight controller"
    for name in sorted(set(before) | set(after)):
        a, b = before.get(name), after.get(name)
        if a != b:
            was = "unset" if a is None else repr(a)
            now = "unset (ArduCopter's default)" if b is None else repr(b)
            changes.append(Change(True, f"flight_controller.{name}: {was} -> {now} ({reload})"))


def _entries(old: Contract, new: Contract, section: str, changes: list[Change],
             compare: Callable[[str, Mapping[str, Any], Mapping[str, Any]], list[Change]]) -> None:
    if section not in old or section not in new:
        return
    before, after = old[section], new[section]
    noun = section[:-1]
    for key in sorted(set(before) | set(after)):
        a, b = before.get(key), after.get(key)
        if a is None:
            changes.append(Change(False, f"{noun} {key} added" + (f" ({b['name']})" if "name" in b else "")))
        elif b is None:
            changes.append(Change(True, f"{noun} {key} removed" + (f" ({a['name']})" if "name" in a else "")))
        elif a != b:
            changes.extend(compare(key, a, b))


def _command_change(code: str, a: Mapping[str, Any], b: Mapping[str, Any]) -> list[Change]:
    out = []
    label = f"command {code} ({b['name']})"
    if (a["min"], a["max"]) != (b["min"], b["max"]):
        narrowed = b["min"] > a["min"] or b["max"] < a["max"]
        out.append(Change(narrowed, f"{label}: range {a['min']}..{a['max']} "
                                    f"{'narrowed' if narrowed else 'widened'} to {b['min']}..{b['max']}"))
    for key in ("target", "sense", "routine", "unit"):
        if a[key] != b[key]:
            out.append(Change(True, f"{label}: {key} {a[key]!r} -> {b[key]!r} (a code reused with another meaning)"))
    for key in ("name", "default", "description"):
        if a[key] != b[key]:
            out.append(Change(False, f"{label}: {key} {a[key]!r} -> {b[key]!r}"))
    return out


def _keyed_change(noun: str, *keys: str) -> Callable[[str, Mapping[str, Any], Mapping[str, Any]], list[Change]]:
    """Compare two entries of a section: a change of one of `keys` breaks a peer, of the description not."""
    def compare(name: str, a: Mapping[str, Any], b: Mapping[str, Any]) -> list[Change]:
        out = [Change(True, f"{noun} {name}: {key} {a.get(key)!r} -> {b.get(key)!r}")
               for key in keys if a.get(key) != b.get(key)]
        if a.get("description") != b.get("description"):
            out.append(Change(False, f"{noun} {name}: description {a.get('description')!r} -> "
                                     f"{b.get('description')!r}"))
        return out
    return compare


def version_problem(old: Contract, new: Contract) -> str | None:
    """Why `new`'s version is wrong after `old` (it must not fall, and must rise on a break), or None."""
    if old.get("name") != new.get("name"):
        return None  # another protocol, not a new version of this one
    before, after = old.get("version", 0), new["version"]
    breaks = [c for c in diff(old, new) if c.breaking]
    if after < before:
        return f"version {after} is lower than the generated version {before}"
    if breaks and after == before:
        return (f"version must rise: {len(breaks)} breaking change{'s' if len(breaks) != 1 else ''} since the "
                f"generated version {before}, first: {breaks[0].what}")
    return None
