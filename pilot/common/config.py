"""Pilot configuration: frozen dataclasses, loaded from and saved to YAML.

Every error names the offending option by its dotted path (``controller.fire_ms``) and the file.
"""

from __future__ import annotations

import dataclasses
import math
import reprlib
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import drone_protocol as dp
import yaml

from .config_file import read_mapping
from .errors import ConfigError
from .ranges import within

HsvTriple = tuple[int, int, int]
HsvRange = tuple[HsvTriple, HsvTriple]

# Red wraps around hue 0 in OpenCV's 0..179 hue scale: it needs two ranges. Hue within 6 units of red
# (8 took in red-brown and orange-red surfaces that joined the ball: bench/vision, tuning photos).
DEFAULT_RED: tuple[HsvRange, ...] = (
    ((0, 120, 70), (6, 255, 255)),
    ((174, 120, 70), (179, 255, 255)),
)


@dataclass(frozen=True)
class HsvConfig:
    ranges: tuple[HsvRange, ...] = DEFAULT_RED
    min_area: int = 30
    open_kernel: int = 3
    target_diameter_m: float = 0.30  # the ball's diameter: apparent size -> range
    min_score: float = 0.2  # candidates scoring below this are not reported at all
    colour_model: str = ""  # the room's learnt colour model (pilot --calibrate BALL --room EMPTY); "": none
    simple: bool = False  # the simpler detector (pilot/vision/ball.py) instead of the rule-grown one (hsv/)


@dataclass(frozen=True)
class VisionConfig:
    """Frame checks and the tracker, shared by both detectors (see pilot/vision/frames.py, pilot/vision/tracking.py)."""

    range_min_m: float = 0.3  # an apparent size implying a range outside this is not the target
    range_max_m: float = 15.0  # a big room's diagonal
    bridge_frames: int = 3  # missed frames the tracker predicts through
    max_jump: float = 0.2  # fraction of the frame width a tracked target may move in one frame
    frozen_frames: int = 5  # identical frames in a row that make the camera count as frozen
    # per-frame detection budget, ms (a quarter of the 20 Hz tick): past it a detector keeps its best candidate so far
    budget_ms: float = 12.5


@dataclass(frozen=True)
class ArucoConfig:
    dictionary: str = "DICT_4X4_50"
    marker_id: int = 7  # -1: any marker
    marker_size_m: float = 0.3
    # OpenCV's default; 3 finds some small, dim, noisy markers (a 0.3 m plate 5 m away) that 7 loses and loses
    # others: over 140 simulated flights both reach 135
    adaptive_thresh_constant: float = 7.0


@dataclass(frozen=True)
class ControllerConfig:
    acquire_frames: int = 3  # consecutive sightings before tracking
    lost_frames: int = 6  # consecutive misses before the target counts as lost
    coast_frames: int = 3  # misses during a forward approach that keep it going
    dead_band_x: float = 0.10  # normalised horizontal image error left alone
    dead_band_y: float = 0.16  # normalised vertical image error left alone
    approach_size: float = 0.19  # apparent size (fraction of frame width) at which approach stops
    retreat_size: float = 0.14  # hysteresis: below this, approach again
    back_off_size: float = 0.3  # above this (closer than the pole's reach), AIM backs off before it fires
    aim_tolerance: float = 0.05  # normalised error within which the aim counts as centred
    aim_frames: int = 3  # centred frames before the laser goes on
    fire_ms: int = 1500  # laser on time
    takeoff_ms: int = 2500  # climb time after arming
    settle_ms: int = 500  # hold after take-off
    search_max_ms: int = 25000  # bounded sweep: give up and land after this
    # the sweep turns for a leg (about one turn at its yaw rate), then moves to another height and turns again:
    # something in front of the target may hide it from one height (down one step first, then up past the start)
    search_leg_ms: int = 7500
    search_step_ms: int = 800  # the climb or descent between legs (full stick)
    # how long LAND waits for the drone to confirm it landed and disarmed (the firmware's landing routine and
    # disarm sequence, plus room for lost frames); then the pilot stops sending and the failsafe takes over
    land_ms: int = dp.LANDING_MS + dp.ARMING_HOLD_MS + 2000
    arm_margin_ms: int = 300  # wait after the drone confirms it armed
    horizontal_fov_deg: float = 60.0  # camera field of view, for pan/tilt corrections and range estimates
    # the gate (pilot/vision/gating.py); figures behind the defaults in bench/vision/RESULTS.md
    # the lowest pair that confirmed none of the tuning photos' empty and distractor sequences (bench/vision)
    acquire_confidence: float = 0.6  # a sighting counts only at or above this confidence
    confirm_frames: int = 3  # measured, confident, centred, in-range frames in a row before the laser may fire
    fire_tolerance: float = 0.10  # normalised error within which a frame counts as centred for the gate
    fire_range_max_m: float = 2.0  # fire only closer than this (aim within 0.8 of it); the simulator judges by it
    blind_frames: int = 20  # bad frames in a row (black, saturated, frozen, malformed) before landing
    # the flight controller holds altitude, not position: the pilot brakes from the closing speed it measures
    brake_mps2: float = 0.5  # deceleration the approach plans with (a 5° lean gives about 0.9 m/s²)
    approach_speed_mps: float = 0.6  # top closing speed
    # one control step of each stick, as the flight controller answers it (pilot/control/pulses.py turns it into a
    # pulse from the spec's channels and the flight controller's parameters): the tuning is in these units
    unit_lean_deg: float = 5.0  # the lean one step of pitch (or roll) asks for
    turn_rate_dps: float = 34.6  # the yaw rate one step of yaw asks for
    climb_mps_per_step: float = 0.47  # AltHold's climb rate for one step of throttle, also for the height estimate
    pitch_accel_mps2: float = 0.8  # what one step of pitch does (its lean, less drag), for dead reckoning


@dataclass(frozen=True)
class LinkConfig:
    rate_hz: float = 20.0
    keepalive_fraction: float = 0.4  # keep-alive period as a fraction of the firmware's command timeout
    ready_timeout_s: float = dp.READY_TIMEOUT_MS / 1000.0  # the spec's
    # how long to try to reopen a lost port before giving up: the firmware's failsafe time (after it the drone
    # is in failsafe and needs a new arming sequence; the flight controller lands it)
    reconnect_s: float = dp.FAILSAFE_TIMEOUT_MS / 1000.0


@dataclass(frozen=True)
class PilotConfig:
    detector: str = "hsv"
    hsv: HsvConfig = field(default_factory=HsvConfig)
    vision: VisionConfig = field(default_factory=VisionConfig)
    aruco: ArucoConfig = field(default_factory=ArucoConfig)
    controller: ControllerConfig = field(default_factory=ControllerConfig)
    link: LinkConfig = field(default_factory=LinkConfig)
    record_failure: str = "continue"  # --record's disk failed: "continue" the flight, or "stop" it (land, disarm)


DETECTORS = ("hsv", "aruco")
RECORD_FAILURES = ("continue", "stop")

T = TypeVar("T")

MAX_INT = 2**53  # no option comes near; beyond, comparisons with floats would overflow
_REPR = reprlib.Repr()
_REPR.maxstring = _REPR.maxother = _REPR.maxlong = 60
_REPR.maxlevel = 3


def _show(value: Any) -> str:
    """A value in a message: on one line and short, whatever the file held (a 10 MB string, a deep list)."""
    return _REPR.repr(value)


def _convert(value: Any, tp: Any, path: str, where: str) -> Any:
    origin = typing.get_origin(tp)
    if dataclasses.is_dataclass(tp) and isinstance(tp, type):
        if not isinstance(value, dict):
            raise ConfigError(f"{where}: option {_show(path)} must be a mapping, got {_show(value)}")
        return _build(tp, value, path, where)
    if tp is bool:
        if not isinstance(value, bool):
            raise ConfigError(f"{where}: option {_show(path)} must be true or false, got {_show(value)}")
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"{where}: option {_show(path)} must be an integer, got {_show(value)}")
        if abs(value) > MAX_INT:
            raise ConfigError(f"{where}: option {_show(path)} is too large a number: {_show(value)}")
        return value
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"{where}: option {_show(path)} must be a number, got {_show(value)}")
        try:
            return float(value)
        except OverflowError as exc:
            raise ConfigError(f"{where}: option {_show(path)} is too large a number: {_show(value)}") from exc
    if tp is str:
        if not isinstance(value, str):
            raise ConfigError(f"{where}: option {_show(path)} must be a string, got {_show(value)}")
        return value
    if origin is tuple:
        args = typing.get_args(tp)
        if not isinstance(value, (list, tuple)):
            raise ConfigError(f"{where}: option {_show(path)} must be a list, got {_show(value)}")
        if len(args) == 2 and args[1] is Ellipsis:
            return tuple(_convert(v, args[0], f"{path}[{i}]", where) for i, v in enumerate(value))
        if len(value) != len(args):
            raise ConfigError(
                f"{where}: option {_show(path)} must have {len(args)} items, got {len(value)}: {_show(value)}"
            )
        return tuple(_convert(v, a, f"{path}[{i}]", where) for i, (v, a) in enumerate(zip(value, args)))
    raise ConfigError(f"{where}: option {_show(path)} has an unsupported type {tp!r}")


def _build(cls: type[T], data: dict[str, Any], prefix: str, where: str) -> T:
    hints = typing.get_type_hints(cls)
    names = {f.name for f in dataclasses.fields(cls)}  # type: ignore[arg-type]
    for key in data:
        if key not in names:
            path = f"{prefix}.{key}" if prefix else str(key)
            raise ConfigError(
                f"{where}: unknown option {_show(path)}; known options here: {', '.join(sorted(names))}"
            )
    kwargs = {
        key: _convert(value, hints[key], f"{prefix}.{key}" if prefix else key, where)
        for key, value in data.items()
    }
    return cls(**kwargs)


# Ranges of the options that feed a safety path or a time limit: (low, high), both inclusive.
_LAND_MIN_MS = dp.LANDING_MS + dp.ARMING_HOLD_MS
RANGES: dict[str, tuple[float, float]] = {
    "controller.acquire_frames": (1, 1000),
    "controller.lost_frames": (1, 1000),
    "controller.coast_frames": (0, 1000),
    "controller.aim_frames": (1, 1000),
    "controller.fire_ms": (1, 60_000),
    "controller.takeoff_ms": (1, 60_000),
    "controller.settle_ms": (0, 60_000),
    "controller.search_max_ms": (1, 600_000),
    "controller.search_leg_ms": (1000, 600_000),
    "controller.search_step_ms": (0, 5_000),
    "controller.land_ms": (_LAND_MIN_MS, 600_000),  # the firmware's landing and disarm must fit
    "controller.arm_margin_ms": (0, 10_000),
    "controller.dead_band_x": (0.0, 1.0),
    "controller.dead_band_y": (0.0, 1.0),
    "controller.approach_size": (0.001, 1.0),
    "controller.retreat_size": (0.0, 1.0),
    "controller.back_off_size": (0.001, 1.0),
    "controller.aim_tolerance": (0.001, 1.0),
    "controller.brake_mps2": (0.05, 5.0),
    "controller.approach_speed_mps": (0.05, 3.0),
    "controller.pitch_accel_mps2": (0.05, 10.0),
    "controller.climb_mps_per_step": (0.01, 5.0),
    "controller.unit_lean_deg": (0.5, 30.0),
    "controller.turn_rate_dps": (1.0, 180.0),
    "link.rate_hz": (1.0, 50.0),
    "link.keepalive_fraction": (0.01, 0.99),
    "link.ready_timeout_s": (0.1, 60.0),
    "link.reconnect_s": (0.0, 60.0),
    "hsv.open_kernel": (1, 99),
    "aruco.adaptive_thresh_constant": (-255.0, 255.0),
}


def _option(config: PilotConfig, path: str) -> Any:
    value: Any = config
    for part in path.split("."):
        value = getattr(value, part)
    return value


def _check_ranges(config: PilotConfig, where: str) -> None:
    for path, (low, high) in RANGES.items():
        _in(where, path, _option(config, path), low, high)


def validate(config: PilotConfig, where: str = "config") -> PilotConfig:
    """Check value ranges; raise ConfigError naming the option."""
    _check_ranges(config, where)
    if config.detector not in DETECTORS:
        raise ConfigError(f"{where}: option 'detector' must be one of {DETECTORS}, got {_show(config.detector)}")
    if config.record_failure not in RECORD_FAILURES:
        raise ConfigError(
            f"{where}: option 'record_failure' must be one of {RECORD_FAILURES}, got {_show(config.record_failure)}"
        )
    for i, (lo, hi) in enumerate(config.hsv.ranges):
        for name, triple in (("low", lo), ("high", hi)):
            h, s, v = triple
            if not (0 <= h <= 179 and 0 <= s <= 255 and 0 <= v <= 255):
                raise ConfigError(
                    f"{where}: option 'hsv.ranges[{i}]' {name} {triple} out of range (H 0..179, S,V 0..255)"
                )
        for channel, low, high in zip("HSV", lo, hi):
            if low > high:  # inRange would match nothing: the detector would never see the target
                wraps = " (a hue range across 179 is two ranges: [174..179] and [0..6])" if channel == "H" else ""
                raise ConfigError(f"{where}: option 'hsv.ranges[{i}]' low {lo} is above high {hi} in {channel}{wraps}")
    if not config.hsv.ranges:
        raise ConfigError(f"{where}: option 'hsv.ranges' must hold at least one range")
    _validate_vision(config, where)
    c = config.controller
    if c.retreat_size >= c.approach_size:
        raise ConfigError(
            f"{where}: option 'controller.retreat_size' ({c.retreat_size}) must be below "
            f"'controller.approach_size' ({c.approach_size}) for the hysteresis to work"
        )
    if c.back_off_size <= c.approach_size:
        raise ConfigError(
            f"{where}: option 'controller.back_off_size' ({c.back_off_size}) must be above "
            f"'controller.approach_size' ({c.approach_size}): AIM would back off from where it stops"
        )
    _fire_range_reached(config, where)
    return config


# AIM fires, and FIRE holds, only within this share of ``controller.fire_range_max_m``: a ball 10 % bigger than
# configured reads 10 % nearer, and the drone drifts while it fires
FIRE_RANGE_SHARE = 0.8


def _fire_range_reached(config: PilotConfig, where: str) -> None:
    """The approach must stop where AIM may fire: else TRACK and AIM hand the drone back and forth for ever."""
    c = config.controller
    size_m = config.aruco.marker_size_m if config.detector == "aruco" else config.hsv.target_diameter_m
    stop_m = size_m / (2.0 * c.approach_size * math.tan(math.radians(c.horizontal_fov_deg) / 2.0))
    if stop_m >= FIRE_RANGE_SHARE * c.fire_range_max_m:
        raise ConfigError(
            f"{where}: option 'controller.fire_range_max_m' ({c.fire_range_max_m:g}) is too short: the approach "
            f"stops about {stop_m:.2f} m from the target ('controller.approach_size' {c.approach_size:g}) and AIM "
            f"fires only within {FIRE_RANGE_SHARE:g} of the range: set it above {stop_m / FIRE_RANGE_SHARE:.2f} m, "
            "or raise approach_size")


def _in(where: str, option: str, value: float, lo: float, hi: float) -> None:
    if not within(value, lo, hi):
        raise ConfigError(f"{where}: option {option!r} must be within {lo:g}..{hi:g}, got {_show(value)}")


def _aruco_dictionary_known(name: str) -> bool:
    import cv2  # here, not at the top: importing the config stays free of OpenCV (about 0.2 s)

    return name.startswith("DICT_") and isinstance(getattr(cv2.aruco, name, None), int)


def _validate_vision(config: PilotConfig, where: str) -> None:
    h, v, c = config.hsv, config.vision, config.controller
    _in(where, "hsv.target_diameter_m", h.target_diameter_m, 0.01, 5.0)
    _in(where, "hsv.min_score", h.min_score, 0.0, 1.0)
    _in(where, "hsv.min_area", h.min_area, 4, 1_000_000)
    _in(where, "aruco.marker_size_m", config.aruco.marker_size_m, 0.01, 5.0)
    if not _aruco_dictionary_known(config.aruco.dictionary):  # checked whichever detector flies: a typo waits
        raise ConfigError(f"{where}: option 'aruco.dictionary' must be one of OpenCV's predefined ArUco "
                          f"dictionaries (DICT_4X4_50, DICT_6X6_250, DICT_APRILTAG_36h11, ...), got "
                          f"{_show(config.aruco.dictionary)}")
    _in(where, "vision.range_min_m", v.range_min_m, 0.0, 100.0)
    _in(where, "vision.range_max_m", v.range_max_m, v.range_min_m + 0.1, 1000.0)
    _in(where, "vision.bridge_frames", v.bridge_frames, 0, 30)
    _in(where, "vision.max_jump", v.max_jump, 0.01, 1.0)
    _in(where, "vision.frozen_frames", v.frozen_frames, 2, 1000)
    # past the tick the loop would miss it whatever the frame shows
    _in(where, "vision.budget_ms", v.budget_ms, 0.1, 1000.0 / config.link.rate_hz)
    _in(where, "controller.horizontal_fov_deg", c.horizontal_fov_deg, 10.0, 170.0)
    _in(where, "controller.acquire_confidence", c.acquire_confidence, 0.05, 1.0)
    _in(where, "controller.confirm_frames", c.confirm_frames, 1, 100)
    _in(where, "controller.fire_tolerance", c.fire_tolerance, c.aim_tolerance, 1.0)
    _in(where, "controller.fire_range_max_m", c.fire_range_max_m, v.range_min_m, v.range_max_m)
    _in(where, "controller.blind_frames", c.blind_frames, 1, 1000)


def from_dict(data: dict[str, Any], where: str = "config") -> PilotConfig:
    return validate(_build(PilotConfig, data, "", where), where)


def load(path: str | Path) -> PilotConfig:
    where = str(path) if str(path).isprintable() else repr(str(path))  # a newline in a name keeps to one line
    return from_dict(read_mapping(Path(path), where), where)


def _plain(value: Any) -> Any:
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


def to_dict(config: PilotConfig) -> dict[str, Any]:
    result: dict[str, Any] = _plain(dataclasses.asdict(config))
    return result


def save(config: PilotConfig, path: str | Path) -> None:
    Path(path).write_text(yaml.safe_dump(to_dict(config), sort_keys=False), encoding="utf-8")
