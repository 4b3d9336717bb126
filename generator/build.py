"""Validate the loaded spec and build the typed model, collecting every error with its location."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import TypeVar

from . import __version__, hardware
from .ardupilot import RC_RANGE_US
from .build_commands import CommandsBuilder
from .diff import Contract, contract, version_problem
from .errors import SpecError, SpecInvalid
from .model import INTEGRITY_MODES, Channel, ErrorKind, Field, Reply, Servo, Settled, Spec
from .names import close_matches, identifier_problem, protocol_name_problem, safe_file_name
from .reader import Reader, is_code, is_int, kind_name, unique_code
from .source import INVALID, Node, display_path, load, read
from .status import read_status
from .widths import overflows

T = TypeVar("T")

# Parser errors the generated code raises itself; the spec gives their codes and descriptions.
# The stream parser's own kinds come first (it counts those in one small array); too_short and too_long are
# whole-frame decode()'s only.
PARSER_ERRORS = ("bad_category", "bad_direction", "bad_digit", "out_of_range", "timeout", "too_short", "too_long")
STREAM_ERRORS = PARSER_ERRORS[:5]
# The ones decode() and encode() raise (timeout is the stream's alone).
FRAME_ERRORS = tuple(e for e in PARSER_ERRORS if e != "timeout")
# Refusals the generated dispatch (unsupported), the integrity check (bad_check) and the firmware reply with.
REFUSALS = ("unsupported", "bad_check", "not_armed", "busy", "armed", "airborne")
REPLIES = ("ready", "accepted", "rejected", "failsafe")
DEFAULT_INTEGRITY = "crc8"
SERVO_FULL_SCALE_DEG = 180  # a hobby servo's full travel, as the Arduino Servo library and the firmware map it
MAX_DIGITS = 4  # value digits of a frame: 16-bit values on the Arduino (a frame is category, direction, digits)


def fingerprint(value: object) -> str:
    canonical = json.dumps(value, sort_keys=True, separators=(",", ":"), ensure_ascii=True)
    return hashlib.sha256(canonical.encode("ascii")).hexdigest()


def load_spec(path: Path, previous: Contract | None = None) -> Spec:
    """Read, validate and build the model of the spec at `path`; raise SpecInvalid with every error.

    `previous`: the contract generated last; the spec's version must rise if it breaks that contract."""
    text, errors = read(path)
    if text is None:
        raise SpecInvalid(errors)
    root, errors = load(text, display_path(path))
    if root is None:
        raise SpecInvalid(errors)
    builder = _Builder(root, safe_file_name(path), errors)
    spec = builder.build()
    if spec is not None and previous is not None:
        problem = version_problem(previous, contract(spec))
        if problem:
            errors.append(SpecError(builder.node_at("protocol.version").location, "protocol.version", problem,
                                    "raise protocol.version (`python -m generator diff` lists the changes); "
                                    "to undo a generated edit, restore generated/ too (git checkout generated)"))
    if errors or spec is None:
        raise SpecInvalid(errors)
    return spec


class _Builder(CommandsBuilder):
    def __init__(self, root: Node, source_name: str, errors: list[SpecError]) -> None:
        self.root, self.source_name, self.errors = root, source_name, errors

    def build(self) -> Spec | None:
        top = Reader(self.root, "", self.errors)
        if not top.ok:
            return None
        protocol = top.section("protocol")
        frame = top.section("frame")
        link = top.section("link")
        safety = top.section("safety")
        modes = top.section("flight_modes")
        speeds = top.section("speeds")

        name = protocol.text("name")
        self._identifier(protocol, "name", name, protocol=True)
        version = protocol.integer("version")
        title = protocol.text("title")
        description = protocol.text("description")
        protocol.finish()

        length = frame.integer("length")
        encoding = frame.get("encoding", str)
        if encoding is not None and encoding != "ascii":
            frame.error(frame.node.children["encoding"], f"unsupported encoding '{encoding}'", "only ascii",
                        frame.sub("encoding"))
        if is_int(frame.node.children.get("length")) and not 3 <= length <= MAX_DIGITS + 2:
            frame.error(frame.node.children["length"], f"frame length {length} is not in 3..{MAX_DIGITS + 2}",
                        f"a frame is category, direction and 1 to {MAX_DIGITS} value digits (16-bit values on the "
                        "Arduino)", frame.sub("length"))
        inter_byte = self._positive(frame, "inter_byte_timeout_ms")
        # A spec without the key gets crc8, the default of new specs (bench/lossy/RESULTS.md has the figures).
        integrity = frame.text("integrity", DEFAULT_INTEGRITY)
        if integrity not in INTEGRITY_MODES:
            near = close_matches(integrity, INTEGRITY_MODES)
            frame.error(frame.node.children["integrity"], f"unknown integrity mode '{integrity}'",
                        f"did you mean '{near[0]}'?" if near else "none or crc8", frame.sub("integrity"))
        frame.finish()

        baud = self._positive(link, "baud")
        data_bits = link.integer("data_bits", 8)
        parity = link.text("parity", "none")
        stop_bits = link.integer("stop_bits", 1)
        # The firmware's UART and the pilot's port are set up for 8N1 only: another framing in the spec would reach
        # the docs and the bench console's Web Serial port, and a peer that believed them would read garbage. (A value
        # of the wrong type is reported by the reader, which then gives the default: no second error here.)
        for key, value, only in (("data_bits", data_bits, 8), ("parity", parity, "none"), ("stop_bits", stop_bits, 1)):
            if value != only:
                link.error(link.node.children[key], f"{key} {value} is not supported: the firmware and the pilot run "
                           "8 data bits, no parity, 1 stop bit", f"write {only} (8N1)", link.sub(key))
        ready_timeout = self._positive(link, "ready_timeout_ms")
        link.finish()

        step = self._positive(speeds, "step_us")
        speeds.finish()
        channels = self._channels(top, step)
        servos = self._servos(top)
        fields = self._fields(top, length)

        stabilize = self._positive(modes, "stabilize_us")
        alt_hold = self._positive(modes, "alt_hold_us")
        modes.finish()
        command_timeout = self._positive(safety, "command_timeout_ms")
        failsafe_timeout = self._positive(safety, "failsafe_timeout_ms")
        failsafe_throttle = self._positive(safety, "failsafe_throttle_us")
        arming_hold = self._positive(safety, "arming_hold_ms")
        landing = self._positive(safety, "landing_ms")
        if command_timeout and failsafe_timeout and command_timeout > failsafe_timeout:
            safety.error(safety.node.children["command_timeout_ms"],
                         "command_timeout_ms is longer than failsafe_timeout_ms",
                         "a movement must end before the failsafe fires", safety.sub("command_timeout_ms"))
        safety.finish()

        categories = self._categories(top, fields, channels, servos)
        replies = self._replies(top)
        errors = self._errors(top)
        status = read_status(top, self.errors)
        settled = self._settled(top)
        project, wiring = hardware.read(top, channels, list(servos), failsafe_throttle, (stabilize, alt_hold))
        flight_controller = hardware.flight_controller(top, channels, wiring, failsafe_throttle, step)
        top.finish()
        if self.errors:
            return None
        spec = Spec(
            source_name=self.source_name,
            fingerprint=fingerprint(self.root.value),
            generator_version=__version__,
            name=name,
            version=version,
            title=title,
            description=description,
            frame_length=length,
            integrity=integrity,
            inter_byte_timeout_ms=inter_byte,
            baud=baud,
            data_bits=data_bits,
            parity=parity,
            stop_bits=stop_bits,
            ready_timeout_ms=ready_timeout,
            channels=tuple(channels.values()),
            speed_step_us=step,
            servos=tuple(servos.values()),
            mode_stabilize_us=stabilize,
            mode_alt_hold_us=alt_hold,
            command_timeout_ms=command_timeout,
            failsafe_timeout_ms=failsafe_timeout,
            failsafe_throttle_us=failsafe_throttle,
            arming_hold_ms=arming_hold,
            landing_ms=landing,
            fields=tuple(f for f, _, _, _ in fields.values()),
            categories=tuple(categories),
            replies=tuple(replies),
            errors=tuple(errors),
            status=status,
            settled=tuple(settled),
            project=project,
            wiring=wiring,
            flight_controller=flight_controller,
        )
        for path, message in overflows(spec):
            node = self.node_at(path)
            self.errors.append(SpecError(node.location, path, message, "the generated C++ would hold another number"))
        return None if self.errors else spec

    def node_at(self, path: str) -> Node:
        """The node the spec writes at dotted `path` (or its nearest parent that exists)."""
        node = self.root
        for key in path.split("."):
            if key not in node.children:
                break
            node = node.children[key]
        return node

    # -- helpers -------------------------------------------------------------------------------------------

    def _positive(self, reader: Reader, key: str) -> int:
        value = reader.integer(key)
        node = reader.node.children.get(key) if reader.ok else None
        if node is not None and is_int(node) and value <= 0:
            reader.error(node, f"{key} must be positive, found {value}", path=reader.sub(key))
        return value

    def _identifier(self, reader: Reader, key: str, name: str, python_only: bool = False,
                    protocol: bool = False) -> bool:
        node = reader.node.children.get(key) if reader.ok else None
        if node is None or not name:
            return False
        problem = protocol_name_problem(name) if protocol else identifier_problem(name, python_only)
        if problem:
            reader.error(node, problem, "names become Python and C++ identifiers", reader.sub(key))
            return False
        return True

    def _pair(self, reader: Reader, key: str) -> tuple[int, int] | None:
        node = reader.child(key)
        if node is None:
            return None
        value = node.value
        if (not isinstance(value, list) or len(value) != 2
                or not all(isinstance(v, int) and not isinstance(v, bool) for v in value)):
            reader.error(node, f"expected [min, max] as two integers, found {value!r}", path=reader.sub(key))
            return None
        lo, hi = int(value[0]), int(value[1])  # type: ignore[arg-type]
        if lo > hi:
            reader.error(node, f"minimum {lo} is greater than maximum {hi}", "write [min, max]", reader.sub(key))
            return None
        if lo < 0:
            reader.error(node, f"minimum {lo} is negative", "values are unsigned decimal digits", reader.sub(key))
            return None
        return lo, hi

    def _named_entries(self, top: Reader, key: str) -> list[tuple[str, Reader]]:
        out = []
        for entry, node in top.entries(key):
            reader = Reader(node, top.sub(key) + "." + entry, self.errors)
            problem = identifier_problem(entry)
            if problem:
                self.errors.append(SpecError(node.key_location, reader.path, problem,
                                             "names become Python and C++ identifiers"))
            elif reader.ok:
                out.append((entry, reader))
        return out

    def _channels(self, top: Reader, step: int) -> dict[str, Channel]:
        channels: dict[str, Channel] = {}
        for name, r in self._named_entries(top, "channels"):
            pair = self._pair(r, "recorded")
            movement = r.text("movement")
            r.finish()
            if pair is None:
                continue
            lo, hi = pair
            low, high = RC_RANGE_US
            if not (low <= lo and hi <= high) and hi <= 0xFFFF:  # past uint16_t: widths.py's error says so
                r.error(r.node.children["recorded"], f"recorded [{lo}, {hi}] is outside {low}..{high} us",
                        "ArduPilot's RCn_MIN and RCn_MAX range: the flight controller reads no stick outside it",
                        r.sub("recorded"))
            median = (lo + hi + 1) // 2  # midpoint rounded half up
            channels[name] = Channel(name, lo, hi, median, median - step, median + step, movement)
        return channels

    def _servos(self, top: Reader) -> dict[str, Servo]:
        servos: dict[str, Servo] = {}
        for name, r in self._named_entries(top, "servos"):
            description = r.text("description")
            pair = self._pair(r, "range_deg")
            default = r.integer("default_deg")
            r.finish()
            if pair is None:
                continue
            if SERVO_FULL_SCALE_DEG < pair[1] <= 0xFF:  # past uint8_t: widths.py's error says so
                r.error(r.node.children["range_deg"], f"maximum {pair[1]} is past {SERVO_FULL_SCALE_DEG} degrees",
                        f"the firmware maps 0..{SERVO_FULL_SCALE_DEG} degrees onto the Arduino Servo library's "
                        "pulses: more would drive the servo past its end", r.sub("range_deg"))
            if not pair[0] <= default <= pair[1]:
                r.error(r.node.children["default_deg"], f"default {default} is outside range {pair[0]}..{pair[1]}",
                        path=r.sub("default_deg"))
            servos[name] = Servo(name, description, pair[0], pair[1], default)
        return servos

    def _fields(self, top: Reader, length: int) -> dict[str, tuple[Field, tuple[int, int] | None, int | None, Node]]:
        fields: dict[str, tuple[Field, tuple[int, int] | None, int | None, Node]] = {}
        for name, r in self._named_entries(top, "fields"):
            width = r.integer("width")
            if not 1 <= width <= MAX_DIGITS:  # checked first: 10 ** width of a hostile width would never finish
                if is_int(r.node.children.get("width")):
                    r.error(r.node.children["width"], f"width {width} is not in 1..{MAX_DIGITS}",
                            f"a value is 1 to {MAX_DIGITS} digits (16-bit values on the Arduino)", r.sub("width"))
                width = 0  # no width: the checks that need one are skipped
            unit = r.text("unit")
            description = r.text("description")
            pair = self._pair(r, "range") if r.node.children.get("range") is not None else None
            r.seen.add("range")
            default = r.get("default", int, required=False)
            parameter = r.text("parameter", "")
            if parameter:
                self._identifier(r, "parameter", parameter, python_only=True)
            r.finish()
            if width and length and width != length - 2:
                r.error(r.node.children["width"], f"width {width} does not fill the frame",
                        f"frame.length {length} leaves {length - 2} value digits", r.sub("width"))
            if pair and width and pair[1] >= 10 ** width:
                r.error(r.node.children["range"], f"maximum {pair[1]} does not fit in {width} digits",
                        f"at most {10 ** width - 1}", r.sub("range"))
            if default is not None and pair and not pair[0] <= default <= pair[1]:
                r.error(r.node.children["default"], f"default {default} is outside range {pair[0]}..{pair[1]}",
                        path=r.sub("default"))
            if not parameter and not (pair and pair[0] == pair[1]):
                r.error(r.node, "missing key 'parameter'", "a field with a range of values needs an argument name",
                        r.sub("parameter"))
            fields[name] = (Field(name, width, unit, description, parameter), pair, default, r.node)
        return fields

    def _replies(self, top: Reader) -> list[Reply]:
        replies = []
        for name, node in top.entries("replies"):
            r = Reader(node, f"replies.{name}", self.errors)
            if name not in REPLIES:
                near = close_matches(name, REPLIES)
                self.errors.append(SpecError(node.key_location, r.path, f"unknown reply '{name}'",
                                             f"did you mean '{near[0]}'?" if near else "known: " + ", ".join(REPLIES)))
                continue
            prefix = r.text("prefix")
            description = r.text("description")
            r.finish()
            if prefix and not all(is_code(c) and c not in "\n" for c in prefix):
                r.error(r.node.children["prefix"], f"prefix {prefix!r} is not printable ASCII", path=r.sub("prefix"))
            replies.append(Reply(name, prefix, description))
        self._require_all(top, "replies", REPLIES, {r.name for r in replies})
        prefixes = [r.prefix for r in replies]
        for reply in replies:
            clash = [p for p in prefixes if p != reply.prefix and p.startswith(reply.prefix)]
            if clash:
                node = top.node.children["replies"].children[reply.name]
                self.errors.append(SpecError(node.location, f"replies.{reply.name}.prefix",
                                             f"prefix '{reply.prefix}' is the start of '{clash[0]}'",
                                             "reply prefixes must not be prefixes of each other"))
        return replies

    def _errors(self, top: Reader) -> list[ErrorKind]:
        kinds: list[ErrorKind] = []
        codes: dict[str, str] = {}
        for name, r in self._named_entries(top, "errors"):
            code = unique_code(r, "error", name, codes)
            description = r.text("description")
            r.finish()
            if code is not None:
                kinds.append(ErrorKind(len(kinds) + 1, name, code, description))
        self._require_all(top, "errors", PARSER_ERRORS + REFUSALS, {k.name for k in kinds})
        # The parser's kinds come first, in a fixed order, so generated code can count them in one array.
        order = sorted(kinds, key=lambda k: (PARSER_ERRORS.index(k.name) if k.name in PARSER_ERRORS
                                             else len(PARSER_ERRORS), k.index))
        return [ErrorKind(i + 1, k.name, k.code, k.description) for i, k in enumerate(order)]

    def _require_all(self, top: Reader, key: str, required: tuple[str, ...], present: set[str]) -> None:
        node = top.node.children.get(key)
        if node is None:
            return
        for name in required:
            if name not in present and name not in node.children:
                self.errors.append(SpecError(node.location, f"{key}.{name}", f"missing {key[:-1]} '{name}'",
                                             "the generated code relies on it"))

    def _settled(self, top: Reader) -> list[Settled]:
        node = top.child("settled", required=False)
        if node is None:
            return []
        if not isinstance(node.value, list):
            if node.value is INVALID:
                return []
            top.error(node, f"expected a list, found {kind_name(node.value)}", path="settled")
            return []
        out = []
        for i, item in enumerate(node.items):
            r = Reader(item, f"settled[{i}]", self.errors)
            if r.ok:
                out.append(Settled(r.text("title"), r.text("seed"), r.text("decision")))
                r.finish()
        return out


