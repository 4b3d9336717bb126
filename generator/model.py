"""The typed model of a validated spec. Templates print these objects and compute nothing themselves."""

from __future__ import annotations

from .records import record


@record
class Channel:
    """One RC channel of Table 4, with the derived speeds."""

    name: str
    recorded_min: int
    recorded_max: int
    median: int
    low: int  # the seed's "40 % speed"
    high: int  # the seed's "60 % speed"
    movement: str

    def speed(self, label: str) -> int:
        return {"low": self.low, "median": self.median, "high": self.high}[label]


@record
class Servo:
    name: str
    description: str
    min_deg: int
    max_deg: int
    default_deg: int


@record
class Field:
    name: str
    width: int
    unit: str
    description: str
    parameter: str  # the argument name of generated functions; "" for a constant field


@record
class Direction:
    code: str
    name: str
    command: str  # function / handler name, e.g. move_forward
    description: str
    field: Field
    minimum: int
    maximum: int
    default: int | None  # None: the value must be given
    default_label: str  # "high", "low", "" ... how the default was chosen
    target: str  # a channel or servo name, "both" or "none"
    sense: int  # +1 / -1 for servo moves, 0 otherwise
    routine: str  # the seed's firmware routine for `i` commands, else ""
    filler: bool  # the direction byte is a filler (laser), not a direction
    safety: str = ""  # what the command does to safety (generator/safety.py SAFETY_EFFECTS); "" for routine

    def frame(self, category: str, value: int) -> str:
        return f"{category}{self.code}{value:0{self.field.width}d}"

    @property
    def default_frame_value(self) -> int:
        return self.minimum if self.default is None else self.default


@record
class Category:
    code: str
    name: str
    hardware: str
    description: str
    directions: tuple[Direction, ...]
    filler: bool


@record
class ByteLookup:
    """A dense table from a byte to an index + 1 (0: none), covering codes first..first + len(entries) - 1.

    The C++ parser looks a byte up in constant time with it, where scanning the spec's lists cost most of
    the parser's cycles on the Arduino."""

    first: int
    entries: tuple[int, ...]


@record
class Command:
    """A (category, direction) pair flattened for the templates."""

    index: int
    category: Category
    direction: Direction


@record
class ErrorKind:
    index: int  # 1-based; 0 is "none" in the C++ enum
    name: str
    code: str
    description: str


@record
class Reply:
    name: str
    prefix: str
    description: str


@record
class StatusState:
    """One state of the drone's state machine as its replies report it."""

    name: str
    code: str
    armed: bool  # the motors may spin in this state
    description: str


@record
class Status:
    """What every accepted, rejected and failsafe reply carries after `separator`: a state code, a laser code."""

    states: tuple[StatusState, ...]
    laser_off: str
    laser_on: str
    separator: str = " "

    def state(self, name: str) -> StatusState:
        return next(s for s in self.states if s.name == name)

    @property
    def length(self) -> int:
        """Characters the status adds to a reply line."""
        return len(self.separator) + 2


@record
class Settled:
    """One inconsistency of the seed document and what the spec decides."""

    title: str
    seed: str
    decision: str


@record
class Vector:
    """One conformance case: a frame and what decoding it must give."""

    frame: bytes
    note: str
    command: str  # "" when the frame is invalid
    category: str
    direction: str
    value: int
    error: str  # "" when valid
    position: int  # byte index of the error, -1 when valid


@record
class FlightControllerSetup:
    """How the flight controller reads the sticks (spec section `flight_controller`, optional)."""

    reversed: tuple[str, ...]  # channels ArduCopter must reverse (RCn_REVERSED, RCn_REV in 3.2)
    throttle_dead_band: int  # THR_DZ, 0-1000 of the throttle range
    firmware: tuple[str, ...]  # the ArduCopter lines to write parameter files for (ardupilot.LINES keys)


@record
class Project:
    """Who publishes the generated library and packages (spec section `project`)."""

    author: str
    maintainer: str
    url: str


@record
class WiredPin:
    name: str  # a channel name or "mode" (RC outputs), a servo name, "laser" or "ppm"
    pin: int  # Arduino pin number
    rc_input: int  # 1-based flight-controller input (RC channel), 0 for outputs that are not RC


@record
class Wiring:
    """Where the firmware's outputs leave the Arduino (spec section `wiring`)."""

    rc_inputs: tuple[WiredPin, ...]  # in the flight controller's input order
    servos: tuple[WiredPin, ...]
    laser: WiredPin
    ppm: WiredPin

    def rc_input(self, name: str) -> int:
        """The flight-controller input an RC output is wired to, 0 when the spec wires none of that name."""
        return next((p.rc_input for p in self.rc_inputs if p.name == name), 0)


@record
class Spec:
    source_name: str
    fingerprint: str  # sha256 of the canonical spec, hex
    generator_version: str
    name: str
    version: int
    title: str
    description: str
    frame_length: int
    integrity: str  # "none" or "crc8" (INTEGRITY_MODES)
    inter_byte_timeout_ms: int
    baud: int
    data_bits: int
    parity: str
    stop_bits: int
    ready_timeout_ms: int
    channels: tuple[Channel, ...]
    speed_step_us: int
    servos: tuple[Servo, ...]
    mode_stabilize_us: int
    mode_alt_hold_us: int
    command_timeout_ms: int
    failsafe_timeout_ms: int
    failsafe_throttle_us: int
    arming_hold_ms: int
    landing_ms: int
    fields: tuple[Field, ...]
    categories: tuple[Category, ...]
    replies: tuple[Reply, ...]
    errors: tuple[ErrorKind, ...]
    status: Status
    settled: tuple[Settled, ...]
    project: Project
    wiring: Wiring
    flight_controller: FlightControllerSetup

    @property
    def package_version(self) -> str:
        """protocol.version as the version of the generated library and packages (semantic: N -> N.0.0)."""
        return f"{self.version}.0.0"

    @property
    def short_fingerprint(self) -> str:
        return self.fingerprint[:16]

    @property
    def commands(self) -> tuple[Command, ...]:
        out: list[Command] = []
        for cat in self.categories:
            for d in cat.directions:
                out.append(Command(len(out), cat, d))
        return tuple(out)

    @property
    def category_lookup(self) -> ByteLookup:
        return _lookup({ord(c.code): i for i, c in enumerate(self.categories)})

    # --- C++ parser tables (firmware helper) ---
    @property
    def direction_lookups(self) -> tuple[ByteLookup, ...]:
        """Per category: its direction bytes to the index within the category + 1 (0: none), for the C++
        parser's constant-time byte-1 lookup."""
        return tuple(_lookup({ord(d.code): i for i, d in enumerate(c.directions)}) for c in self.categories)
    # --- end of C++ parser tables ---

    @property
    def category_ranges(self) -> tuple[tuple[int, int], ...]:
        """(index of the first command, number of commands) of each category, in order."""
        out, first = [], 0
        for cat in self.categories:
            out.append((first, len(cat.directions)))
            first += len(cat.directions)
        return tuple(out)

    @property
    def targets(self) -> tuple[str, ...]:
        """Every output a command can drive, in a stable order (C++ Target enum after None)."""
        return tuple(c.name for c in self.channels) + tuple(s.name for s in self.servos) + ("both",)

    def reply(self, name: str) -> Reply:
        return next(r for r in self.replies if r.name == name)

    @property
    def reply_max_length(self) -> int:
        """The longest reply line in bytes, "\n" included: `READY name fingerprint16 integrity`, or a prefix, two
        bytes (category and direction, or an error code) and the status; each with "*XX" in crc8 mode."""
        check = 1 + self.check_length if self.check_length else 0
        ready = (len(self.reply("ready").prefix) + 1 + len(self.name) + 1 + len(self.short_fingerprint) + 1
                 + len(self.integrity) + check + 1)
        return max(ready, max(len(r.prefix) for r in self.replies) + 2 + self.status.length + check + 1)

    @property
    def digits_width(self) -> int:
        return self.frame_length - 2

    @property
    def check_length(self) -> int:
        """Check characters after the frame's bytes on the wire (two hex digits in crc8 mode)."""
        return CHECK_LENGTH[self.integrity]

    @property
    def wire_length(self) -> int:
        return self.frame_length + self.check_length

    def error(self, name: str) -> ErrorKind:
        return next(e for e in self.errors if e.name == name)

    def wire(self, text: str) -> str:
        """A frame or reply line as it goes on the wire: with its check in crc8 mode (a reply's after '*')."""
        if self.integrity == "none":
            return text
        data = text.encode("ascii")
        return text + check_text(data) if len(data) == self.frame_length else text + "*" + check_text(data)


# frame.integrity modes and the check characters each appends to a frame.
CHECK_LENGTH = {"none": 0, "crc8": 2}
INTEGRITY_MODES = tuple(CHECK_LENGTH)


def crc8(data: bytes) -> int:
    """CRC-8/SMBUS (poly 0x07, init 0, no reflection): the check of frame.integrity crc8."""
    crc = 0
    for byte in data:
        crc ^= byte
        for _ in range(8):
            crc = ((crc << 1) ^ 0x07) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc


def check_text(data: bytes) -> str:
    """The two upper-case hex digits appended to a frame (or after '*' to a reply) in crc8 mode."""
    return f"{crc8(data):02X}"


def _lookup(index_by_code: dict[int, int]) -> ByteLookup:
    first, last = min(index_by_code), max(index_by_code)
    return ByteLookup(first, tuple(index_by_code.get(code, -1) + 1 for code in range(first, last + 1)))
