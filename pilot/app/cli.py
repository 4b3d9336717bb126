"""``python -m pilot`` / ``pilot``: fly the simulated room (the default) or a real drone.

    pilot                                    # simulated room, virtual drone, default scenario
    pilot --scenario behind --seed 4 --record out/
    pilot --port /dev/ttyACM0 --arm --camera 0
    pilot --video flight.mp4 --dry-run       # decide and print the commands, send nothing
    pilot --calibrate sample.png --config pilot.yaml   # HSV ranges from a sample image into the config
    pilot --calibrate ball*.png --room empty*.png --config pilot.yaml   # learn the room's colour model
    pilot check --port /dev/ttyACM0          # guided bring-up of the bench, propellers off
    pilot report out/                        # one HTML page from a --record folder
"""

from __future__ import annotations

import argparse
import dataclasses
import signal
import sys
from collections.abc import Sequence
from types import FrameType
from typing import TYPE_CHECKING

import drone_protocol as dp

from ..common import config as config_mod
from ..common.config import PilotConfig
from ..common.errors import PilotError
from ..common.version import __version__
from ..control.controller import Controller, State
from ..link.protocol_needs import protocol_problem
from ..link.serial_link import Link, LogEntry, keepalive_ms
from ..vision.calibrate import Roi, calibrate_to_config, preview_path
from ..vision.calibrate_room import learn_room, room_summary
from ..vision.detect import make_detector
from ..vision.picam import PicameraSource
from .cli_options import MAX_VIEWERS, LiveSession, check_sources, port_error_hint, stop_note
from .liveserver import DEFAULT_LIMITS
from .observers import LaserTally
from .record import Recorder, summary_lines
from .runner import DryRunSink, Observer, RealPacer, Sink, StatusLine, run

if TYPE_CHECKING:
    from .sim_flight import FlightResult
from ..sim.room import SCENARIOS, make_scenario  # data only: the simulator itself (MuJoCo) is imported when used
from ..vision.sources import CameraSource, Frame, FrameSource, ImageFolderSource, VideoFileSource

EXIT_OK = 0
EXIT_FAILED = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130
MAX_SIZE = (4096, 4096)  # the simulated camera's largest frame (about 50 MB of BGR)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="pilot", description="The Raspberry Pi vision pilot of the drone.",
                                epilog="pilot check --port PORT: guided bring-up of the bench (propellers off). "
                                "pilot report DIR: one HTML page from a --record folder.")
    p.add_argument("--version", action="version", version=f"pilot {__version__} (protocol {dp.PROTOCOL_NAME} "
                   f"{dp.PROTOCOL_VERSION}, spec fingerprint {dp.SPEC_FINGERPRINT})")
    where = p.add_argument_group("where to fly")
    where.add_argument("--sim", action="store_true", help="fly the simulated room (the default without --port)")
    where.add_argument("--port", help="serial port or pyserial URL of the drone's Arduino (e.g. /dev/ttyACM0)")
    where.add_argument("--baud", type=int, default=dp.BAUD, help=f"baud rate (default {dp.BAUD}, from the spec)")
    where.add_argument("--arm", action="store_true", help="allow arming a real drone (required with --port)")
    src = p.add_argument_group("frames (real flights and --dry-run)")
    src.add_argument("--camera", help="camera index or device (V4L2, default 0 with --port), or picam for the "
                     "Raspberry Pi camera through picamera2")
    src.add_argument("--video", help="a video file as the frame source")
    src.add_argument("--images", help="a folder of images as the frame source")
    p.add_argument("--detector", choices=config_mod.DETECTORS, help="target detector (default: config, else hsv)")
    p.add_argument("--config", help="YAML config file (see pilot/common/config.py for every option)")
    p.add_argument("--dry-run", action="store_true", help="decide and print the commands, send nothing")
    p.add_argument("--record", metavar="DIR", help="write the annotated video, the JSON-lines log and the path picture")
    p.add_argument("--force", action="store_true", help="let --record overwrite an earlier recording in DIR")
    p.add_argument("--serve", metavar="[HOST:]PORT", help="serve a live view with an emergency Stop (host "
                   "127.0.0.1 unless given; the URL, with its token, is printed at start-up)")
    p.add_argument("--serve-viewers", type=int, default=DEFAULT_LIMITS.viewers, metavar="N",
                   help=f"live view: video streams at once, 1..{MAX_VIEWERS} (default {DEFAULT_LIMITS.viewers})")
    p.add_argument("--seed", type=int, default=1, help="simulated room seed (default 1)")
    p.add_argument("--scenario", choices=SCENARIOS, default="ahead", help="simulated scenario (default ahead)")
    p.add_argument("--max-seconds", type=float, default=60.0, help="flight time limit, seconds (default 60)")
    p.add_argument("--wind", type=float, default=0.0, help="simulated steady wind, up to this many m/s (default 0)")
    p.add_argument("--ideal", action="store_true",
                   help="simulated world without its randomised effects (airframe, estimation, latency, camera)")
    p.add_argument("--gusts", type=float, default=0.0, help="simulated gusts of about this many m/s (default 0)")
    p.add_argument("--camera-fault", metavar="KIND@START+SECONDS",
                   help="simulated camera fault: black, saturated, frozen, small or grey, from START seconds "
                        "(or 'fire': when the laser first comes on), e.g. black@8+3")
    p.add_argument("--size", default="320x240", help="simulated camera frame size (default 320x240)")
    p.add_argument("--readout-ms", type=float, default=0.0,
                   help="simulated rolling shutter: ms from the top row to the bottom one (default 0: global shutter; "
                        "a Raspberry Pi camera module reads out in about 20-30 ms)")
    p.add_argument("--virtual-drone", help="the virtual drone executable (default: the firmware's host build)")
    p.add_argument("--no-status", action="store_true", help="no status line")
    cal = p.add_argument_group("calibration")
    cal.add_argument("--calibrate", metavar="IMAGE", nargs="+",
                     help="pick HSV ranges from IMAGE and save them to --config; with --room: learn the room's colour "
                          "model from frames (images or a short video) of the ball held in the middle of the view")
    cal.add_argument("--room", metavar="FRAMES", nargs="+",
                     help="with --calibrate: frames (images or a short video) of the room without the ball, at the "
                          "camera's size (--size)")
    cal.add_argument("--roi", help="x,y,w,h of the target in the calibration image (default: the central 20%%)")
    return p


class _Terminated(KeyboardInterrupt):
    """SIGTERM, handled like Ctrl-C: the safe sequence goes out before the program ends."""


def _on_sigterm(signum: int, frame: FrameType | None) -> None:
    raise _Terminated(f"signal {signum}")


def _load_config(args: argparse.Namespace) -> PilotConfig:
    cfg = config_mod.load(args.config) if args.config else PilotConfig()
    if args.detector:
        cfg = dataclasses.replace(cfg, detector=args.detector)
    return config_mod.validate(cfg, args.config or "command line")


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError as exc:
        raise PilotError(f"option --size: expected WIDTHxHEIGHT, got {text!r}") from exc
    if not (32 <= w <= MAX_SIZE[0] and 24 <= h <= MAX_SIZE[1]):
        raise PilotError(
            f"option --size: {text!r} must be within 32x24..{MAX_SIZE[0]}x{MAX_SIZE[1]} (width x height)"
        )
    return w, h


def _check_args(args: argparse.Namespace) -> None:
    """Options that bound the flight or feed the link: finite, in range, named when they are not."""
    checks = (
        ("--max-seconds", args.max_seconds, 0.0 < args.max_seconds <= 86_400.0, "above 0 and at most 86400"),
        ("--wind", args.wind, 0.0 <= args.wind <= 50.0, "within 0..50"),
        ("--gusts", args.gusts, 0.0 <= args.gusts <= 20.0, "within 0..20"),
        ("--readout-ms", args.readout_ms, 0.0 <= args.readout_ms <= 1000.0, "within 0..1000"),
        ("--baud", args.baud, 0 < args.baud <= 4_000_000, "within 1..4000000"),
        ("--seed", args.seed, args.seed >= 0, "0 or more"),  # numpy's seed sequences take no negative number
    )
    for option, value, ok, allowed in checks:
        if not ok:  # NaN fails every comparison, infinities the upper bounds
            raise PilotError(f"option {option} must be {allowed}, got {value!r}")
    _size(args.size)
    if args.camera_fault is not None:
        from ..sim.world import CameraFault  # the simulator's own check (MuJoCo is not imported by this)

        try:
            CameraFault.parse(args.camera_fault)
        except PilotError as exc:
            raise PilotError(f"option --camera-fault: {exc}") from exc


def _roi(text: str | None) -> Roi | None:
    if text is None:
        return None
    try:
        x, y, w, h = (int(v) for v in text.split(","))
    except ValueError as exc:
        raise PilotError(f"option --roi: expected x,y,w,h, got {text!r}") from exc
    return (x, y, w, h)


class _StillSim:
    """--dry-run without a frame source: the simulated room seen from the start pose, at altitude."""

    def __init__(self, scenario_name: str, seed: int, size: tuple[int, int]) -> None:
        from ..sim.camera import CameraModel
        from ..sim.still import StillView

        self.view = StillView(make_scenario(scenario_name, seed), CameraModel(*size))
        self._index = 0

    def read(self) -> Frame | None:
        frame = Frame(self.view.render(self._index * 0.05), self._index * 0.05, self._index)
        self._index += 1
        return frame

    def close(self) -> None:
        self.view.close()

    def __enter__(self) -> _StillSim:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _frame_source(args: argparse.Namespace) -> FrameSource | _StillSim:
    if args.video:
        return VideoFileSource(args.video)
    if args.images:
        return ImageFolderSource(args.images)
    if args.camera is not None or args.port:
        cam = args.camera if args.camera is not None else "0"
        if cam == "picam":
            return PicameraSource()
        return CameraSource(int(cam) if cam.isdigit() else cam)
    return _StillSim(args.scenario, args.seed, _size(args.size))


def _fly_sim(args: argparse.Namespace, cfg: PilotConfig) -> int:
    observers: list[Observer] = []
    status = None if args.no_status else StatusLine()
    if status is not None:
        observers.append(status)
    live = LiveSession(args.serve, simulated=True, viewers=args.serve_viewers) if args.serve else None
    if live is not None:
        observers.extend(live.observers())
    try:
        result = _fly_sim_with(args, cfg, observers)
    finally:
        if live is not None:
            live.close("the flight is over")
    stop_note(live)
    if status is not None:
        status.finish()
    print(result.summary())
    print(f"drone:     laser {'ON' if result.final_laser else 'off'}, {'armed' if result.final_armed else 'disarmed'}, "
          f"altitude {result.final_altitude:.2f} m (the virtual drone's outputs at the end)")
    if result.record_dir:
        print("\n".join(summary_lines(result.record_dir, result.record_failed, simulated=True,
                                       picture=result.path_picture)))
    if result.error:
        print(f"pilot: stopped by {result.error}", file=sys.stderr)
    if result.error and ("KeyboardInterrupt" in result.error or "StopRequested" in result.error):
        return EXIT_INTERRUPTED
    return EXIT_OK if result.success and result.wall_hits == 0 else EXIT_FAILED


def _fly_sim_with(args: argparse.Namespace, cfg: PilotConfig, observers: list[Observer]) -> FlightResult:
    from ..sim.camera import CameraModel
    from .sim_flight import fly

    return fly(
        args.scenario,
        args.seed,
        config=cfg,
        max_seconds=args.max_seconds,
        record_dir=args.record,
        camera=CameraModel(*_size(args.size), readout_s=args.readout_ms / 1000.0),
        executable=args.virtual_drone,
        observers=observers,
        max_wind=args.wind,
        gusts=args.gusts,
        fault=args.camera_fault,
        ideal=args.ideal,
    )


def _fly_real(args: argparse.Namespace, cfg: PilotConfig) -> int:
    if args.port and not args.dry_run and not args.arm:
        print(
            f"pilot: refusing to fly the drone on {args.port}: arming a real drone needs --arm "
            "(or use --dry-run to print the commands without sending them)",
            file=sys.stderr,
        )
        return EXIT_USAGE
    # the recording and the live view start once the frame source and the link are open, so that a
    # failure there leaves no half-written recording behind
    recorder: Recorder | None = None
    live: LiveSession | None = None
    early: list[LogEntry] = []  # link traffic before the recorder exists (the ready line)
    tally = LaserTally()
    observers: list[Observer] = [tally]
    status = None if args.no_status else StatusLine()
    if status is not None:
        observers.append(status)

    def link_log(entry: LogEntry) -> None:
        if recorder is not None:
            recorder.on_link(entry)
        else:
            early.append(entry)

    link: Link | None = None
    try:
        with _frame_source(args) as source:
            sink: Sink
            if args.dry_run:
                sink = DryRunSink()
            else:
                link = Link(
                    args.port,
                    args.baud,
                    ready_timeout_s=cfg.link.ready_timeout_s,
                    reconnect_s=cfg.link.reconnect_s,
                    log=link_log,
                )
                try:
                    link.open()
                except PilotError as exc:
                    hint = port_error_hint(exc, args.port)
                    if hint is None:
                        raise
                    raise hint from exc
                sink = link
            if args.record:
                recorder = Recorder(args.record, fps=cfg.link.rate_hz, on_failure=cfg.record_failure)
                observers.append(recorder)
                for entry in early:
                    recorder.on_link(entry)
            if args.serve:
                live = LiveSession(args.serve, simulated=False, viewers=args.serve_viewers)
                observers.extend(live.observers())
            controller = Controller(cfg.controller)
            result = run(
                source,
                make_detector(cfg),
                controller,
                sink,
                RealPacer(cfg.link.rate_hz),
                max_seconds=args.max_seconds,
                keepalive_ms=keepalive_ms(cfg.link.keepalive_fraction),
                observers=observers,
            )
    finally:
        if live is not None:
            live.close("the flight is over")
        if link is not None:
            link.close()
        if recorder is not None:
            recorder.write({"result": {"note": "real flight: no position, so no path picture"}})
            recorder.close()
        if status is not None:
            status.finish()
    stop_note(live)
    print(f"pilot: {result.reason}; final state {result.state.value}; {tally.summary()}")
    print(f"pilot: the drone confirmed: {result.confirmed}")
    if result.port_lost:
        print(f"pilot: {result.port_lost}", file=sys.stderr)
    for problem in result.shutdown_errors:
        print(f"pilot: during the safe shutdown: {problem}", file=sys.stderr)
    if recorder is not None:
        print("\n".join(summary_lines(recorder.dir, recorder.failed, simulated=False)))
    if isinstance(result.error, KeyboardInterrupt):
        return EXIT_INTERRUPTED
    if result.error is not None and not isinstance(result.error, PilotError):
        print(f"pilot: stopped by {type(result.error).__name__}: {result.error}", file=sys.stderr)
    done = result.state is State.DONE and result.error is None and result.fired
    return EXIT_OK if done else EXIT_FAILED


def main(argv: Sequence[str] | None = None) -> int:
    words = list(sys.argv[1:] if argv is None else argv)
    if words[:1] == ["check"]:  # pilot check --port PORT: the guided bring-up of the bench
        from .check import main as check_main

        return check_main(words[1:])
    if words[:1] == ["report"]:  # pilot report DIR: one HTML page from a --record folder
        from .report import main as report_main

        return report_main(words[1:])
    args = build_parser().parse_args(words)
    previous = signal.signal(signal.SIGTERM, _on_sigterm)
    try:
        if args.calibrate:
            if not args.config:
                raise PilotError("option --calibrate needs --config FILE to save the calibration into")
            if args.room:
                report = learn_room(args.calibrate, args.room, args.config, _roi(args.roi), _size(args.size))
                print(room_summary(report))
                return EXIT_OK
            if len(args.calibrate) > 1:
                raise PilotError("option --calibrate: one sample image, or frames of the ball with --room FRAMES")
            cfg = calibrate_to_config(args.calibrate[0], args.config, _roi(args.roi))
            print(f"pilot: saved HSV ranges {cfg.hsv.ranges} to {args.config}; preview {preview_path(args.config)}")
            return EXIT_OK
        if (problem := protocol_problem()) is not None:  # a spec edit the pilot cannot fly with
            raise PilotError(problem)
        check_sources(args)
        _check_args(args)
        cfg = _load_config(args)
        if args.port and args.sim:
            raise PilotError("options --sim and --port exclude each other")
        if args.sim:
            return _fly_sim(args, cfg)
        if args.port or args.dry_run or args.camera is not None or args.video or args.images:
            if not args.port:
                args.dry_run = True  # frames without a drone: decide and print
            return _fly_real(args, cfg)
        return _fly_sim(args, cfg)
    except PilotError as exc:
        print(f"pilot: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    finally:
        signal.signal(signal.SIGTERM, previous)
