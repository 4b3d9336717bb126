"""A short libFuzzer run over the whole firmware logic (firmware/host/fuzz_drone.cpp), under ASan and UBSan.

The target checks, after every byte and pause, the promises of the firmware: outputs inside Table 4 (the failsafe
throttle excepted), failsafe no later than its time, throttle at minimum on the ground, armed only through an
arm frame, a movement deflecting one stick for at most the command timeout. Seeds (built here from the spec's
conformance vectors) arm the drone and fly it, so the fuzzer starts from deep states instead of the boot state.
"""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path

import drone_protocol as dp
import fwsupport as fw

FUZZ_SECONDS = 10
MAX_PAUSE = 127  # the target's pause byte carries 0..127 ms


def pairs(frame: bytes, pause: int = 0) -> bytes:
    """Encode serial bytes for the target: (pause, byte) pairs, the pause before the first byte."""
    out = b""
    for k, byte in enumerate(frame):
        out += bytes([pause if k == 0 else 0, byte])
    return out


def wait(ms: int, keepalive: bytes) -> bytes:
    """Let `ms` pass, sending `keepalive` every ~500 ms so that the failsafe stays away."""
    out, waited = b"", 0
    while waited < ms:
        for _ in range(4):
            out += bytes([MAX_PAUSE, 0xFF])  # 0xFF: a garbage byte, answered once and otherwise ignored
        waited += 4 * MAX_PAUSE
        out += pairs(keepalive)
    return out


def seeds() -> dict[str, bytes]:
    vectors = json.loads((fw.ROOT / "generated" / "vectors.json").read_text())["vectors"]
    valid = [bytes.fromhex(v["frame_hex"]) for v in vectors if v["ok"]]
    armed = pairs(dp.arm()) + wait(dp.ARMING_HOLD_MS + 100, dp.servo_reset())
    fly = b"".join(pairs(f, pause=40) for f in valid if f[:1] in (b"m", b"t"))
    return {
        "all_vectors": b"".join(pairs(f, pause=30) for f in valid),
        "arm_and_fly": armed + pairs(dp.hold_altitude()) + fly + wait(1500, dp.hold_altitude()),
        "arm_then_silence": armed + pairs(dp.move_up(1621)) + bytes([MAX_PAUSE, 0xFF]) * 12,
        "self_test": pairs(dp.first_test()) + wait(5000, dp.laser_toggle()),
        "disarm_while_moving": armed + pairs(dp.turn_left(1424)) + pairs(dp.disarm(), pause=100)
        + wait(dp.ARMING_HOLD_MS + 100, dp.servo_up(10)),
    }  # fmt: skip


def test_fuzzing_the_firmware_logic_finds_no_broken_promise(tmp_path: Path) -> None:
    fw.make("firmware-host")
    corpus = tmp_path / "corpus"
    corpus.mkdir()
    for name, data in seeds().items():
        (corpus / name).write_bytes(data)
    vectors = json.loads((fw.ROOT / "generated" / "vectors.json").read_text())["vectors"]
    entries = sorted({pairs(bytes.fromhex(v["frame_hex"])) for v in vectors if v["ok"]})
    dictionary = tmp_path / "frames.dict"
    dictionary.write_text("".join('"' + "".join(f"\\x{b:02x}" for b in e) + '"\n' for e in entries))
    result = subprocess.run(
        [
            str(fw.BUILD / "host" / "fuzz_drone"),
            f"-max_total_time={FUZZ_SECONDS}",
            "-max_len=4096",
            f"-dict={dictionary}",
            f"-artifact_prefix={tmp_path}/",
            str(corpus),
        ],
        capture_output=True,
        text=True,
        timeout=FUZZ_SECONDS + 60,
        check=False,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    done = re.search(r"Done (\d+) runs", result.stderr)
    assert done and int(done.group(1)) > 1000, result.stderr[-2000:]
