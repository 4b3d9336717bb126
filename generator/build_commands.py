"""Build the categories and their directions (the commands) from the spec: the largest part of validation."""

from __future__ import annotations

from typing import Optional, TypeVar

from .errors import SpecError
from .model import Category, Channel, Direction, Field, Servo
from .names import close_matches, identifier_problem
from .reader import Reader, is_code
from .safety import SAFETY_EFFECTS
from .source import Node

T = TypeVar("T")
SPEED_LABELS = ("low", "median", "high")
FieldEntry = tuple[Field, Optional[tuple[int, int]], Optional[int], Node]


class CommandsBuilder:
    """The category and direction part of the spec builder (generator.build._Builder mixes it in)."""

    errors: list[SpecError]

    def _identifier(self, reader: Reader, key: str, name: str, python_only: bool = False,
                    protocol: bool = False) -> bool:
        raise NotImplementedError  # generator.build._Builder defines it

    def _categories(self, top: Reader, fields: dict[str, tuple[Field, tuple[int, int] | None, int | None, Node]],
                    channels: dict[str, Channel], servos: dict[str, Servo]) -> list[Category]:
        categories: list[Category] = []
        commands: dict[str, str] = {}
        for code, node in top.entries("categories"):
            path = f"categories.{code}"
            if not is_code(code):
                self.errors.append(SpecError(node.key_location, path, f"category code {code!r} is not one printable "
                                             "ASCII character", "use one letter, e.g. 'm'"))
                continue
            if code.isdigit():
                self.errors.append(SpecError(node.key_location, path, f"category code '{code}' is a digit",
                                             "a digit would be mistaken for a value byte when resynchronising"))
                continue
            r = Reader(node, path, self.errors)
            if not r.ok:
                continue
            name = r.text("name")
            name_ok = self._identifier(r, "name", name)
            hardware = r.text("hardware")
            description = r.text("description")
            default_field = r.get("field", str, required=False)
            filler_code = r.get("filler", str, required=False)
            prefix: str | None = r.get("command_prefix", str, required=False)
            if prefix is None and "command_prefix" not in r.node.children:
                prefix = f"{name}_" if name_ok else None  # unknown: its commands' names can't be checked
            if default_field is not None and default_field not in fields:
                self._unknown(r, "field", default_field, fields)
            directions = []
            entries = r.entries("directions")
            for dcode, dnode in entries:
                d = self._direction(r, dcode, dnode, prefix, default_field, filler_code, fields, channels,
                                    servos)
                if d is None:
                    continue
                if d.command in commands:
                    self.errors.append(SpecError(dnode.location, f"{path}.directions.{dcode}",
                                                 f"command name '{d.command}' is already used by "
                                                 f"{commands[d.command]}", "rename the direction"))
                    continue
                commands[d.command] = f"{code}{dcode}"
                directions.append(d)
            if filler_code is not None and len(entries) > 1:
                r.error(r.node.children["filler"], "a category with a filler byte has exactly one direction",
                        path=r.sub("filler"))
            r.finish()
            if name_ok:
                categories.append(Category(code, name, hardware, description, tuple(directions),
                                           filler_code is not None))
        seen: dict[str, str] = {}
        for cat in categories:
            if cat.name in seen or cat.name in commands:
                node = top.node.children["categories"].children[cat.code].children["name"]
                self.errors.append(SpecError(node.location, f"categories.{cat.code}.name",
                                             f"name '{cat.name}' is already used",
                                             "category and command names must all differ"))
            seen[cat.name] = cat.code
        return categories

    def _unknown(self, r: Reader, key: str, value: str, known: dict[str, T]) -> None:
        near = close_matches(value, sorted(known))
        hint = f"did you mean '{near[0]}'?" if near else "known: " + ", ".join(sorted(known))
        r.error(r.node.children[key], f"unknown {key} '{value}'", hint, r.sub(key))

    def _direction(self, cat: Reader, dcode: str, node: Node, prefix: str | None, default_field: str | None,
                   filler_code: str | None, fields: dict[str, tuple[Field, tuple[int, int] | None, int | None, Node]],
                   channels: dict[str, Channel], servos: dict[str, Servo]) -> Direction | None:
        path = f"{cat.path}.directions.{dcode}"
        if not is_code(dcode):
            self.errors.append(SpecError(node.key_location, path, f"direction code {dcode!r} is not one printable "
                                         "ASCII character", "use one letter, e.g. 'f'"))
            return None
        if filler_code is not None and dcode != filler_code:
            self.errors.append(SpecError(node.key_location, path, f"direction '{dcode}' differs from the "
                                         f"category's filler '{filler_code}'"))
            return None
        r = Reader(node, path, self.errors)
        if not r.ok:
            return None
        name = r.text("name")
        name_ok = self._identifier(r, "name", name)
        description = r.text("description")
        field_name = r.get("field", str, default_field, required=False)
        channel_name = r.get("channel", str, required=False)
        servo_name = r.get("servo", str, required=False)
        sense = r.get("sense", int, required=False)
        routine = r.text("routine", "")
        safety = r.text("safety", "")
        if safety and safety not in SAFETY_EFFECTS:
            near = close_matches(safety, SAFETY_EFFECTS)
            r.error(r.node.children["safety"], f"unknown safety effect '{safety}'",
                    f"did you mean '{near[0]}'?" if near else "known: " + ", ".join(SAFETY_EFFECTS), r.sub("safety"))
        default_node = r.node.children.get("default")
        r.seen.add("default")
        r.finish()
        if field_name is None:
            r.error(r.node, "missing key 'field'", "give the direction or its category a field", r.sub("field"))
            return None
        if field_name not in fields:
            if "field" in r.node.children:
                self._unknown(r, "field", field_name, fields)
            return None
        fld, pair, fdefault, _ = fields[field_name]
        target, label, default = "none", "", fdefault
        if channel_name is not None:
            if channel_name not in channels:
                self._unknown(r, "channel", channel_name, channels)
                return None
            channel = channels[channel_name]
            target = channel_name
            if pair is None:
                pair = (channel.recorded_min, channel.recorded_max)
        if servo_name is not None:
            if servo_name != "both" and servo_name not in servos:
                self._unknown(r, "servo", servo_name, {**servos, "both": None})
                return None
            target = servo_name
        if servo_name is not None and channel_name is not None:
            r.error(r.node, "a direction drives a channel or a servo, not both", path=path)
            return None
        if sense is not None and sense not in (-1, 1):
            r.error(r.node.children["sense"], f"sense must be 1 or -1, found {sense}", path=r.sub("sense"))
        if pair is None:
            r.error(r.node, f"field '{field_name}' has no range and the direction drives no channel",
                    "give the field a range or the direction a channel", path)
            return None
        if default_node is not None:
            value = default_node.value
            if isinstance(value, str) and channel_name is not None:
                if value not in SPEED_LABELS:
                    near = close_matches(value, SPEED_LABELS)
                    r.error(default_node, f"unknown speed '{value}'",
                            f"did you mean '{near[0]}'?" if near else "low, median or high", r.sub("default"))
                    return None
                label, default = value, channels[channel_name].speed(value)
            elif isinstance(value, int) and not isinstance(value, bool):
                default = value
            else:
                r.error(default_node, f"expected an integer or low/median/high, found {value!r}",
                        path=r.sub("default"))
                return None
        if fld.width and pair[1] >= 10 ** fld.width:  # no width: its own error is reported
            r.error(r.node, f"range {pair[0]}..{pair[1]} does not fit in {fld.width} digits", path=path)
            return None
        if default is not None and not pair[0] <= default <= pair[1]:
            where = default_node if default_node is not None else r.node
            r.error(where, f"default {default} is outside range {pair[0]}..{pair[1]}", path=r.sub("default"))
            return None
        if not name_ok or prefix is None:
            return None
        command = f"{prefix}{name}"
        problem = identifier_problem(command)
        if problem:
            r.error(r.node.children["name"], problem, "change the name or the category's command_prefix",
                    r.sub("name"))
            return None
        return Direction(dcode, name, command, description, fld, pair[0], pair[1], default, label, target,
                         sense or 0, routine, filler_code is not None, safety if safety in SAFETY_EFFECTS else "")
