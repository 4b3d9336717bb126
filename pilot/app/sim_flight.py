"""One simulated flight, end to end, and many of them in a process pool.

The pilot (controller, detector, link) flies against the real virtual drone: frames go over the
virtual drone's pseudo-terminal through pyserial, the firmware's clock is stepped one tick at a
time, and the world follows its RC outputs. The link's ready-line wait uses the world's clock too
(its "sleep" steps the firmware), so nothing waits in real time.
"""

from __future__ import annotations

import dataclasses
import multiprocessing
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

from ..common.config import LinkConfig, PilotConfig
from ..control.controller import Controller, State
from ..link.serial_link import Link, LogEntry, keepalive_ms
from ..sim.camera import CameraModel
from ..sim.room import make_scenario
from ..sim.virtual import VirtualDrone
from ..sim.world import BOOT_MS, CameraFault, SimWorld
from ..vision.detect import make_detector
from .record import Recorder
from .runner import Observer, run


def failures(*, fire_ms: int, longest_on_target_ms: int, fired: bool, non_target_hits: int, what: Sequence[str],
             wall_hits: int, crashes: int, landed_disarmed: bool, laser_off: bool,
             error: str | None) -> tuple[str, ...]:
    """Why a flight failed (nothing: it succeeded). A success keeps the laser spot on the target without a break
    for the fire time, completes the fire, lights nothing else, touches no wall, and ends landed and disarmed."""
    out: list[str] = []
    if longest_on_target_ms < fire_ms:
        out.append(f"spot on the target {longest_on_target_ms} ms at most without a break (fire time {fire_ms} ms)")
    if not fired:
        out.append("the fire did not complete")
    if non_target_hits:
        out.append(f"{non_target_hits} non-target hit(s) ({', '.join(what)})")
    if wall_hits:
        out.append(f"{wall_hits} wall touch(es)")
    if crashes:
        out.append(f"{crashes} crash(es)")
    if not landed_disarmed:
        out.append("did not land and disarm")
    if not laser_off:
        out.append("laser left on")
    if error:
        out.append(f"pilot stopped by {error}")
    return tuple(out)


def time_to_target(runs: Sequence[Sequence[int]], fire_ms: int) -> float | None:
    """Seconds from the start to the stay of the spot on the target that lasted the fire time (None: none did)."""
    return next((start / 1000.0 for start, length in runs if length >= fire_ms), None)


@dataclass(frozen=True)
class FlightResult:
    scenario: str
    seed: int
    detector: str
    success: bool  # strict: see ``failures``
    lit_on_target_ms: int
    lit_elsewhere_ms: int
    non_target_hits: int  # the laser came onto something that is not the target
    reached: bool
    min_distance: float
    wall_hits: int
    crashes: int
    fired: bool
    reason: str
    final_state: str
    sim_seconds: float
    wall_seconds: float
    frames_sent: int
    reconnects: int
    final_laser: bool  # the virtual drone's laser pin at the end
    final_armed: bool  # the firmware's state
    final_fc_armed: bool  # the emulated flight controller's, from the sticks
    final_altitude: float
    confirmed: str = ""  # what the drone's last status reply said (state, laser)
    record_dir: str | None = None
    path_picture: str | None = None
    video: str | None = None
    record_failed: str = ""  # why the recording stopped early, if it did
    error: str | None = None
    physics_ms: float = 0.0  # wall time in physics and the flight controller
    render_ms: float = 0.0  # wall time in MuJoCo's renderer
    sensor_ms: float = 0.0  # wall time in the camera sensor's effects
    frames: int = 0
    non_target_what: tuple[str, ...] = ()
    lit_during_fault_ms: int = 0  # laser on while the camera was faulty (a fault injected with ``fault``)
    landed_because: str = ""  # the reason of the controller's move to LAND
    longest_on_target_ms: int = 0  # the longest unbroken stay of the laser spot on the target
    fire_ms: int = 0  # the configured fire time the stay must last
    time_to_target_s: float | None = None  # from the start to the stay that lasted the fire time
    failures: tuple[str, ...] = ()  # why it failed (empty: success)

    def summary(self) -> str:
        verdict = "SUCCESS" if self.success else "FAILED"
        to_target = "-" if self.time_to_target_s is None else f"{self.time_to_target_s:4.1f} s"
        return (
            f"{self.scenario:10s} seed {self.seed:3d} {self.detector:5s} {verdict:7s} "
            f"on target {self.longest_on_target_ms:5d}/{self.fire_ms} ms unbroken, time to target {to_target} "
            f"min dist {self.min_distance:4.2f} m walls {self.wall_hits} crashes {self.crashes} "
            f"non-target {self.non_target_hits} "
            f"sim {self.sim_seconds:5.1f} s wall {self.wall_seconds:5.2f} s ({self.reason})"
            + ("" if self.confirmed in self.reason else f"; drone confirmed {self.confirmed}")
            + ("" if self.success else f" -- failed: {'; '.join(self.failures)}")
        )


@dataclass(frozen=True)
class FlightJob:
    scenario: str
    seed: int
    detector: str = "hsv"
    max_seconds: float = 60.0
    noise: bool = True
    width: int = 320
    height: int = 240
    executable: str | None = None
    max_wind: float = 0.0
    gusts: float = 0.0
    fault: str | None = None  # a camera fault, KIND@START+DURATION (world.CameraFault)
    ideal: bool = False  # the randomised world's effects off (pilot/sim/randomise.py)
    record_dir: str | None = None  # the flight's video and log (as `pilot --record`)


def sim_link(
    world: SimWorld, vd: VirtualDrone, cfg: LinkConfig, log: Callable[[LogEntry], None] | None = None
) -> Link:
    """The pilot's link to the virtual drone's pty, stamped with the world's clock and made the world's step
    barrier (both ways, so a flight is deterministic under any load); not yet open."""
    link = Link(
        vd.pty,
        ready_timeout_s=cfg.ready_timeout_s,
        reconnect_s=cfg.reconnect_s,
        clock=world.now,
        log=log,
        # opening the pty reboots the virtual board: run it for BOOT_MS (it sends its ready line well within),
        # then wait in real time for the kernel to move the bytes through the pty, so that the flight's
        # simulated timeline does not depend on that
        on_open=lambda: world.advance(BOOT_MS),
        ready_clock=time.monotonic,
        ready_sleep=time.sleep,
    )
    world.link = link
    return link


def fly(
    scenario_name: str,
    seed: int,
    *,
    config: PilotConfig | None = None,
    detector_name: str | None = None,
    max_seconds: float = 60.0,
    record_dir: str | Path | None = None,
    camera: CameraModel | None = None,
    noise: bool = True,
    executable: str | Path | None = None,
    lose_camera_at_s: float | None = None,
    observers: Sequence[Observer] = (),
    max_wind: float = 0.0,
    gusts: float = 0.0,
    fault: str | None = None,
    ideal: bool = False,
) -> FlightResult:
    cfg = config or PilotConfig()
    if detector_name is not None:
        cfg = dataclasses.replace(cfg, detector=detector_name)
    scenario = make_scenario(scenario_name, seed, noise=noise, max_wind=max_wind, gusts=gusts, ideal=ideal)
    # a flight is deterministic for its seed: the detector's budget counts simulated time, in which a look takes none
    detector = make_detector(cfg, clock=lambda: 0.0)
    recorder = None
    if record_dir is not None:
        recorder = Recorder(record_dir, fps=cfg.link.rate_hz, on_failure=cfg.record_failure)
    wall0 = time.perf_counter()
    tick_ms = round(1000.0 / cfg.link.rate_hz)
    try:
        with (
            VirtualDrone(executable) as vd,
            SimWorld(
                scenario,
                vd,
                camera,
                tick_ms=tick_ms,
                aim_point="marker" if cfg.detector == "aruco" else "ball",
                lose_camera_at_s=lose_camera_at_s,
                fault=CameraFault.parse(fault) if fault else None,
                reach_m=cfg.controller.fire_range_max_m,  # the mission's reach: a stay counts within it
            ) as world,
        ):

            def link_log(entry: LogEntry) -> None:
                if recorder is not None:
                    recorder.on_link(entry)

            link = sim_link(world, vd, cfg.link, link_log)
            with link:
                controller = Controller(cfg.controller, clock=world.now)
                watchers: list[Observer] = list(observers)
                if recorder is not None:
                    watchers.append(recorder)
                result = run(
                    world.camera(),
                    detector,
                    controller,
                    link,
                    world,
                    max_seconds=max_seconds,
                    keepalive_ms=keepalive_ms(cfg.link.keepalive_fraction),
                    observers=watchers,
                )
            score = world.score
            state = world.state
            picture = None
            if recorder is not None:
                drawn = recorder.path_png(scenario, score.path)
                picture = str(drawn) if drawn is not None else None
                recorder.write(
                    {
                        "result": {
                            "reason": result.reason,
                            "transitions": [
                                {"t_ms": t.t_ms, "from": t.old.value, "to": t.new.value, "why": t.reason}
                                for t in controller.transitions
                            ],
                            "lit_on_target_ms": score.lit_on_target_ms,
                            "wall_hits": state.wall_hits,
                            "crashes": state.crashes,
                        }
                    }
                )
                recorder.close()  # now: a last flush that fails is in the result's record_failed
            error = None if result.error is None else f"{type(result.error).__name__}: {result.error}"
            fire_ms = cfg.controller.fire_ms
            failed = failures(
                fire_ms=fire_ms, longest_on_target_ms=score.longest_on_target_ms, fired=result.fired,
                non_target_hits=score.non_target_hits, what=score.non_target_what, wall_hits=state.wall_hits,
                crashes=state.crashes, landed_disarmed=not (state.armed or world.outputs.armed),
                laser_off=not world.outputs.laser, error=error)
            return FlightResult(
                scenario=scenario_name,
                seed=seed,
                detector=cfg.detector,
                success=not failed,
                lit_on_target_ms=score.lit_on_target_ms,
                lit_elsewhere_ms=score.lit_elsewhere_ms,
                non_target_hits=score.non_target_hits,
                reached=score.reached,
                min_distance=score.min_distance,
                wall_hits=state.wall_hits,
                crashes=state.crashes,
                fired=result.fired,
                reason=result.reason,
                final_state=result.state.value if isinstance(result.state, State) else str(result.state),
                sim_seconds=world.now(),
                wall_seconds=time.perf_counter() - wall0,
                frames_sent=len(link.sent),
                reconnects=link.reconnects,
                final_laser=world.outputs.laser,
                final_armed=world.outputs.armed,
                final_fc_armed=state.armed,
                final_altitude=state.z,
                confirmed=result.confirmed,
                record_dir=str(recorder.dir) if recorder is not None else None,
                path_picture=picture,
                video=str(recorder.video_path) if recorder is not None else None,
                record_failed=recorder.failed if recorder is not None else "",
                physics_ms=score.physics_ms,
                render_ms=score.render_ms,
                sensor_ms=score.sensor_ms,
                frames=score.frames,
                non_target_what=tuple(score.non_target_what),
                lit_during_fault_ms=score.lit_during_fault_ms,
                landed_because=next((t.reason for t in controller.transitions if t.new is State.LAND), ""),
                error=error,
                longest_on_target_ms=score.longest_on_target_ms,
                fire_ms=fire_ms,
                time_to_target_s=time_to_target(score.on_target_runs, fire_ms),
                failures=failed,
            )
    finally:
        if recorder is not None:
            recorder.close()


def _fly_job(job: FlightJob) -> FlightResult:
    return fly(
        job.scenario,
        job.seed,
        detector_name=job.detector,
        max_seconds=job.max_seconds,
        noise=job.noise,
        camera=CameraModel(job.width, job.height),
        executable=job.executable,
        max_wind=job.max_wind,
        gusts=job.gusts,
        fault=job.fault,
        ideal=job.ideal,
        record_dir=job.record_dir,
    )


def fly_many(jobs: Iterable[FlightJob], processes: int | None = None) -> list[FlightResult]:
    """Flights in a process pool (one virtual drone per flight), results in job order."""
    todo = list(jobs)
    if processes == 1 or len(todo) <= 1:
        return [_fly_job(job) for job in todo]
    ctx = multiprocessing.get_context("spawn")  # a forked child would inherit MuJoCo's GL context
    with ctx.Pool(processes or None) as pool:
        return pool.map(_fly_job, todo, chunksize=1)
