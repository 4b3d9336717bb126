"""The real AVR binary in simavr: pulse widths from cycle counts, the laser pin, and the UART replies.

The firmware is built by `make firmware`; the harness is firmware/sim/drone_sim.c. The conformance vectors
come from generated/vectors.json (written by the generator from the spec).
"""

from __future__ import annotations

import itertools
import json
import random
from dataclasses import dataclass, field
from typing import Any

import drone_protocol as dp
import fwsupport as fw
import pytest

TOLERANCE_US = 2.0
SLOT_MS = 60.0  # one vector per slot: the new pulses start at the next 20 ms frame boundary
SETTLE_MS = 25.0  # pulses measured from this far into a slot (one frame + margin) to its end
VECTORS: list[dict[str, Any]] = json.loads((fw.ROOT / "generated" / "vectors.json").read_text())["vectors"]
VALID = [v for v in VECTORS if v["ok"]]
MALFORMED = [v for v in VECTORS if not v["ok"]]


@pytest.fixture(scope="module", autouse=True)
def built() -> None:
    fw.make("firmware")


def reply(line: bytes) -> str:
    return line.decode().rstrip("\n")


@dataclass
class Model:
    """What the firmware should output (the spec's rules, as the README states them)."""

    sticks: dict[str, int] = field(default_factory=fw.at_boot)
    mode: int = dp.MODE_STABILIZE_US
    pan: int = dp.SERVOS[dp.ServoName.PAN].default
    tilt: int = dp.SERVOS[dp.ServoName.TILT].default
    laser: bool = False

    def widths(self) -> dict[str, int]:
        return {**self.sticks, "mode": self.mode, "pan": fw.servo_us(self.pan), "tilt": fw.servo_us(self.tilt)}


@dataclass
class Plan:
    """A simulation script with, per slot, what to check."""

    events: list[tuple[float, bytes]] = field(default_factory=list)
    checks: list[tuple[float, float, dict[str, int], bool | None, list[str], str]] = field(default_factory=list)
    t: float = 50.0

    def send(self, data: bytes, dt: float = 0.0) -> None:
        self.events.append((self.t + dt, data))

    def check(self, widths: dict[str, int], laser: bool | None, replies: list[str], label: str) -> None:
        self.checks.append((self.t, self.t + SLOT_MS, widths, laser, replies, label))

    def wait(self, ms: float) -> None:
        self.t += ms


def arm(plan: Plan, model: Model) -> None:
    """Arm, keeping the link alive with servo_reset frames (which change nothing at the defaults)."""
    plan.send(dp.arm())
    for k in range(1, 8):
        plan.send(dp.servo_reset(), dt=300.0 * k)
    plan.wait(dp.ARMING_HOLD_MS + 150)
    model.sticks = fw.on_ground()


def verify(result: fw.SimResult, plan: Plan) -> None:
    for start, end, widths, laser, replies, label in plan.checks:
        for name, expected in widths.items():
            seen = result.widths_us(fw.PINS[name], start + SETTLE_MS, end)
            assert seen, f"{label}: no pulse on {name}"
            worst = max(abs(w - expected) for w in seen)
            assert worst <= TOLERANCE_US, f"{label}: {name} {seen} != {expected} us"
        if laser is not None:
            assert result.laser_at(end) == int(laser), f"{label}: laser"
        got = result.replies_between(start, end)
        assert got[: len(replies)] == replies, f"{label}: replies {got}"


def test_every_valid_vector_gives_its_pulses_and_reply() -> None:
    plan, model = Plan(), Model()
    arm(plan, model)
    plan.send(dp.hold_altitude())
    model.sticks, model.mode = fw.neutral(), dp.MODE_ALT_HOLD_US
    plan.wait(SLOT_MS)
    by_category: dict[str, list[dict[str, Any]]] = {}
    for v in VALID:
        by_category.setdefault(v["category"], []).append(v)
    # Movements and turns, armed: the frame's channel gets the value, every other stick its median.
    for v in by_category["m"] + by_category["t"]:
        spec = dp.COMMANDS[v["command"]]
        frame = bytes.fromhex(v["frame_hex"])
        plan.send(frame)
        plan.check(
            {**fw.neutral(), spec.target: v["value"], "mode": model.mode},
            None,
            [fw.R.accepted(frame)],
            v["frame"],
        )
        plan.wait(SLOT_MS)
    plan.send(dp.hold_altitude())
    plan.wait(dp.COMMAND_TIMEOUT_MS + 100)  # the last movement has timed out: sticks neutral again
    # Servos: relative moves clamped to the range, and reset.
    for v in by_category["s"]:
        spec = dp.COMMANDS[v["command"]]
        frame = bytes.fromhex(v["frame_hex"])
        if spec.target == "both":
            model.pan, model.tilt = dp.SERVOS[dp.ServoName.PAN].default, dp.SERVOS[dp.ServoName.TILT].default
        else:
            limits = dp.SERVOS[spec.target]
            now = getattr(model, spec.target)
            setattr(model, spec.target, max(limits.minimum, min(limits.maximum, now + spec.sense * v["value"])))
        plan.send(frame)
        plan.check(model.widths(), model.laser, [fw.R.accepted(frame)], v["frame"])
        plan.wait(SLOT_MS)
    laser_after = {"laser_on": True, "laser_off": False}  # the toggle inverts it
    for v in by_category["l"]:
        frame = bytes.fromhex(v["frame_hex"])
        model.laser = laser_after.get(v["command"], not model.laser)
        plan.send(frame)
        plan.check(model.widths(), model.laser, [fw.R.accepted(frame)], v["frame"])
        plan.wait(SLOT_MS)
    init = {v["command"]: bytes.fromhex(v["frame_hex"]) for v in by_category["i"]}
    assert set(init) == {"arm", "disarm", "hold_altitude", "first_test", "land", "query_status"}, \
        "a new init routine needs a check here"
    plan.send(init["query_status"])  # changes nothing
    plan.check(model.widths(), model.laser, [fw.R.accepted(init["query_status"])], "iq")
    plan.wait(SLOT_MS)
    plan.send(init["hold_altitude"])
    plan.check(model.widths(), model.laser, [fw.R.accepted(init["hold_altitude"])], "is")
    plan.wait(SLOT_MS)
    plan.send(init["arm"])  # already armed: accepted, nothing changes
    plan.check(model.widths(), model.laser, [fw.R.accepted(init["arm"])], "ia armed")
    plan.wait(SLOT_MS)
    plan.send(init["first_test"])  # never while armed
    plan.check(model.widths(), model.laser, [fw.R.rejected("armed")], "it armed")
    plan.wait(SLOT_MS)
    plan.send(init["disarm"])  # in the air: refused, land instead
    plan.check(model.widths(), model.laser, [fw.R.rejected("airborne")], "ik airborne")
    plan.wait(SLOT_MS)
    plan.send(init["land"])  # alt-hold, throttle at its low speed for the landing time
    model.sticks = {**fw.neutral(), "throttle": dp.CHANNELS[dp.ChannelName.THROTTLE].low}
    plan.check(model.widths(), model.laser, [fw.R.accepted(init["land"])], "il")
    for k in range(1, (fw.SPEC.landing_ms + dp.ARMING_HOLD_MS) // 300 + 1):
        plan.send(init["land"], dt=300.0 * k)  # il0000 is the keep-alive while landing
    # the check window opens just before the first keep-alive of the disarm sequence (one every 300 ms)
    plan.wait((fw.SPEC.landing_ms // 300 + 1) * 300 - 30)
    model.sticks = {**fw.on_ground(), "yaw": dp.CHANNELS[dp.ChannelName.YAW].minimum}  # then the disarm sequence
    model.mode = dp.MODE_STABILIZE_US
    model.laser = False
    plan.check(model.widths(), model.laser, [fw.R.accepted(init["land"])], "disarming")
    plan.wait(dp.ARMING_HOLD_MS)
    model.sticks = fw.on_ground()
    plan.check(model.widths(), model.laser, [], "disarmed")
    plan.wait(SLOT_MS)
    plan.send(init["first_test"])  # disarmed: the self-test starts by moving the pan servo to its minimum
    plan.check(
        {**fw.on_ground(), "pan": fw.servo_us(dp.SERVOS[dp.ServoName.PAN].minimum)},
        None,
        [fw.R.accepted(init["first_test"])],
        "it disarmed",
    )
    plan.wait(SLOT_MS)
    result = fw.simulate(plan.events, plan.t)
    assert result.end["unsent"] == 0
    assert fw.R.ready() == result.replies()[0]
    verify(result, plan)
    assert fw.R.failsafe() not in result.replies()


def test_every_malformed_vector_changes_no_output() -> None:
    plan, model = Plan(), Model()
    arm(plan, model)
    plan.send(dp.hold_altitude() + dp.laser_toggle())
    model.sticks, model.mode, model.laser = fw.neutral(), dp.MODE_ALT_HOLD_US, True
    plan.wait(SLOT_MS)
    keepalive = dp.hold_altitude()  # changes nothing while holding
    slot = 40.0
    follow_ups: list[tuple[float, str]] = []
    for v in MALFORMED:
        frame = bytes.fromhex(v["frame_hex"])
        if v["error"] == "too_long":
            # No delimiter on the wire: the first six bytes are a valid frame and the seventh a stray byte
            # (test_too_long_frame_on_the_stream_is_a_frame_and_a_stray_byte).
            continue
        plan.send(keepalive)
        plan.send(frame, dt=5.0)
        expected = [fw.R.accepted(keepalive)]
        kind = dp.ErrorKind[v["error"].upper()]
        if kind == dp.ErrorKind.TOO_SHORT:
            if frame:
                # A stream parser cannot know a frame is short until the next byte comes too late.
                follow_ups.append((plan.t + slot, fw.R.rejected("timeout")))
        else:
            expected.append(fw.R.rejected(kind.name.lower()))
        plan.checks.append((plan.t, plan.t + slot, model.widths(), model.laser, expected, v["frame"]))
        plan.t += slot
    result = fw.simulate(plan.events, plan.t + slot)
    for start, end, widths, laser, replies, label in plan.checks:
        for name, want in widths.items():
            seen = result.widths_us(fw.PINS[name], start, end)
            assert seen and max(abs(w - want) for w in seen) <= TOLERANCE_US, f"{label}: {name} {seen}"
        assert result.laser_at(end) == int(bool(laser)), label
        # A rejected frame can leave a valid-looking tail in the parser ("ml0999" -> "l0999"), which the next
        # byte, 35 ms later, drops as a timeout: that "Et" may open the following slot.
        got = result.replies_between(start, end)
        got = got[1:] if got and got[0] == fw.R.rejected("timeout") else got
        assert got[: len(replies)] == replies, f"{label}: {got}"
        assert [r for r in got if r.startswith("A")] == [replies[0]], f"{label}: {got}"
    for t, first in follow_ups:
        assert result.replies_between(t, t + 10)[0] == first
    assert fw.R.failsafe() not in result.replies()


def test_too_long_frame_on_the_stream_is_a_frame_and_a_stray_byte() -> None:
    (v,) = [v for v in MALFORMED if v["error"] == "too_long"]
    frame = bytes.fromhex(v["frame_hex"])
    plan, model = Plan(), Model()
    arm(plan, model)
    plan.send(frame)
    result = fw.simulate(plan.events, plan.t + 40)
    head = dp.decode(frame[:6])
    replies = result.replies_between(plan.t, plan.t + 40)
    assert replies == [fw.R.accepted(head.encode()), fw.R.rejected("bad_category")]
    target = dp.COMMANDS[head.name].target
    assert all(abs(w - head.value) <= TOLERANCE_US for w in result.widths_us(fw.PINS[target], plan.t + 25, plan.t + 40))


def test_failsafe_fires_at_its_time_on_the_real_binary() -> None:
    plan, model = Plan(), Model()
    arm(plan, model)  # armed on the ground: the throttle at its minimum until the failsafe
    plan.send(dp.laser_toggle())
    last_frame_ms = plan.t
    end = last_frame_ms + dp.FAILSAFE_TIMEOUT_MS + 100
    result = fw.simulate(plan.events, end)
    (t_fs,) = [t for t, text in result.tx if fw.R.body(text.rstrip("\n")) == fw.R.failsafe()]
    frame_done_ms = last_frame_ms + len(dp.laser_toggle()) * 10_000 / dp.BAUD  # 10 bits per byte
    fired_ms = t_fs / 16000
    # millis() ticks every 1.024 ms on a 16 MHz AVR: the deadline is met to within its resolution.
    assert abs(fired_ms - (frame_done_ms + dp.FAILSAFE_TIMEOUT_MS)) <= 2
    assert result.laser_at(fired_ms - 5) == 1 and result.laser_at(fired_ms + 1) == 0
    throttle = fw.PINS["throttle"]
    before = result.widths_us(throttle, last_frame_ms, fired_ms - 1)
    after = result.widths_us(throttle, fired_ms + 21, end)
    assert before and all(abs(w - dp.CHANNELS[dp.ChannelName.THROTTLE].minimum) <= TOLERANCE_US for w in before)
    assert after and all(abs(w - dp.FAILSAFE_THROTTLE_US) <= TOLERANCE_US for w in after)
    for name in ("roll", "pitch", "yaw"):
        seen = result.widths_us(fw.PINS[name], fired_ms + 21, end)
        assert seen and all(abs(w - dp.CHANNELS[name].median) <= TOLERANCE_US for w in seen)


def test_garbage_between_frames_never_changes_an_output_to_an_uncommanded_value() -> None:
    rng = random.Random(1234)
    plan, model = Plan(), Model()
    arm(plan, model)
    commanded: dict[str, set[int]] = {
        name: {fw.neutral()[name], fw.on_ground()[name], fw.at_boot()[name]} for name in fw.STICKS
    }
    commanded["yaw"].add(dp.CHANNELS[dp.ChannelName.YAW].maximum)  # the arming hold
    frames_sent: list[bytes] = []
    sticks = [s for s in dp.COMMANDS.values() if s.category in (dp.Category.MOVE, dp.Category.TURN)]
    for _ in range(60):
        spec = rng.choice(sticks)
        value = rng.randint(spec.minimum, spec.maximum)
        frame = dp.encode(spec.category, spec.direction, value)
        commanded[spec.target].add(value)
        frames_sent.append(frame)
        garbage = bytes(rng.randrange(256) for _ in range(rng.randint(1, 40)))
        plan.send(garbage + frame)  # garbage right before the frame, no pause between
        plan.wait(rng.uniform(15, 120))
    result = fw.simulate(plan.events, plan.t + 50)
    start = plan.events[0][0]
    for name in fw.STICKS:
        widths = result.widths_us(fw.PINS[name], start, plan.t + 50)
        stray = [w for w in widths if min(abs(w - c) for c in commanded[name]) > TOLERANCE_US]
        assert not stray, f"{name}: uncommanded widths {sorted(set(stray))[:5]}"
    assert result.laser_at(plan.t + 50) == 0 and not result.levels, "the laser was never commanded"
    accepted = [r for r in result.replies() if r.startswith("A")]
    expected = [fw.R.accepted(f) for f in frames_sent]
    assert accepted[-len(expected) :] == expected  # every frame found, nothing else accepted
    assert fw.R.failsafe() not in result.replies()


def test_pulse_jitter_stays_within_tolerance_under_back_to_back_frames() -> None:
    plan = Plan()
    frame = dp.laser_toggle()
    per_frame_ms = len(frame) * 10_000 / dp.BAUD
    for k in range(1500):  # about 0.8 s of frames back to back at full line rate
        plan.events.append((100 + k * per_frame_ms, frame))
    result = fw.simulate(plan.events, 1000)
    # every frame was parsed and acted on while the pulses ran: the laser toggled 1500 times
    toggles = sum(1 for (_, a), (_, b) in itertools.pairwise(result.levels) if a != b)
    assert toggles >= 1500 - 1 and result.laser_at(1000) == 0
    # A reply (with its status) is longer than a frame: back to back, the transmit line limits the replies and
    # the rest are dropped, never waited on.
    reply_bytes = len(fw.R.line(fw.R.accepted(frame), "disarmed", False)) + 1
    answered = result.replies().count(fw.R.accepted(frame))
    assert 0.95 * 1500 * len(frame) / reply_bytes <= answered <= 1500
    for name, pin in fw.PINS.items():
        widths = result.widths_us(pin, 150, 950)
        assert len(widths) >= 35, name
        assert max(widths) - min(widths) <= 1.0, f"{name}: {min(widths)}..{max(widths)} us"


def test_mega_2560_build_drives_the_same_arduino_pins() -> None:
    result = fw.simulate(
        [(50, dp.laser_toggle() + dp.servo_right(45))], 200, elf=fw.BUILD / "mega" / "mega.elf", mcu="atmega2560"
    )
    assert result.replies()[:3] == [fw.R.ready(), fw.R.accepted(dp.laser_toggle()), fw.R.accepted(dp.servo_right(45))]
    expected = {
        **fw.at_boot(),
        "mode": dp.MODE_STABILIZE_US,
        "pan": fw.servo_us(dp.SERVOS[dp.ServoName.PAN].default + 45),
        "tilt": fw.servo_us(dp.SERVOS[dp.ServoName.TILT].default),
    }
    for name, want in expected.items():
        seen = result.widths_us(fw.PINS[name], 100, 200)
        assert seen and max(abs(w - want) for w in seen) <= TOLERANCE_US, (name, seen)
    assert result.laser_at(199) == 1


def test_ppm_build_sends_the_rc_channels_as_one_ppm_sum_train() -> None:
    result = fw.simulate([(50, dp.servo_left(30))], 300, elf=fw.BUILD / "uno_ppm" / "uno_ppm.elf")
    ppm = fw.PINS["roll"]  # the PPM line replaces the roll output (pins.h)
    rises = [rise / fw.CYCLES_PER_US for rise, _ in result.pulses[ppm] if rise > 100 * 16000]
    # Frames: 6 separator pulses (5 channels + the closing one), then the sync gap.
    gaps = [b - a for a, b in itertools.pairwise(rises)]
    frame_starts = [i + 1 for i, g in enumerate(gaps) if g > 3000]
    assert len(frame_starts) >= 5
    i = frame_starts[0]
    channels = [rises[i + k + 1] - rises[i + k] for k in range(5)]
    expected = [
        fw.at_boot()["roll"],
        fw.at_boot()["pitch"],
        fw.at_boot()["throttle"],
        fw.at_boot()["yaw"],
        dp.MODE_STABILIZE_US,
    ]
    assert all(abs(c - e) <= TOLERANCE_US for c, e in zip(channels, expected, strict=True)), channels
    period = rises[frame_starts[1]] - rises[frame_starts[0]]
    assert abs(period - 22500) <= TOLERANCE_US
    for name in ("pitch", "throttle", "yaw", "mode"):
        assert fw.PINS[name] not in result.pulses, name  # parallel outputs are silent in the PPM build
    pan = result.widths_us(fw.PINS["pan"], 100, 300)
    assert pan and all(abs(w - fw.servo_us(dp.SERVOS[dp.ServoName.PAN].default - 30)) <= TOLERANCE_US for w in pan)
