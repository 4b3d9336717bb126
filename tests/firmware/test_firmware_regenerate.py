"""The "build the firmware from generated sources" path end to end: edit the spec (add a direction),
regenerate into a temporary folder, rebuild the AVR firmware against it, and fly the new command in simavr.
No firmware source is touched: the new direction reaches the generic move handler through dispatch().
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import drone_protocol as dp
import fwsupport as fw
import yaml

NEW_DIRECTION = "g"  # a "glide forward" on the pitch channel, unknown to the committed spec
NEW_FRAME = b"mg1700"


def test_a_direction_added_to_the_spec_is_accepted_by_the_rebuilt_firmware(tmp_path: Path) -> None:
    spec = yaml.safe_load((fw.ROOT / "spec" / "drone.yaml").read_text())
    directions = spec["categories"]["m"]["directions"]
    assert NEW_DIRECTION not in directions
    directions[NEW_DIRECTION] = {
        "name": "glide_forward",
        "description": "Glide forward",
        "channel": "pitch",
        "default": "high",
    }
    spec_path = tmp_path / "drone.yaml"
    spec_path.write_text(yaml.safe_dump(spec, sort_keys=False, allow_unicode=True))
    out = tmp_path / "generated"
    subprocess.run(
        [sys.executable, "-m", "generator", "--spec", str(spec_path), "--out", str(out)], cwd=fw.ROOT, check=True
    )
    library = out / "arduino" / "DroneProtocol"
    header = (library / "src" / "DroneProtocol.h").read_text()
    assert "'m', 'g'" in header
    build = tmp_path / "build"
    fw.make("firmware-sim")  # the simavr harness, which this test may be the first to need
    # Cores are shared with the main build (FW_CORE_BUILD): only the sketch is rebuilt.
    fw.make(
        str(build / "uno" / "uno.elf"),
        DRONE_PROTOCOL_DIR=str(library),
        FW_BUILD=str(build),
        FW_CORE_BUILD=str(fw.BUILD),
    )

    fingerprint = re.search(r'SPEC_FINGERPRINT\[\] = "([0-9a-f]+)"', header)
    assert fingerprint and fingerprint.group(1) != dp.SPEC_FINGERPRINT

    # Arm (with keep-alives), then the new command, then check pitch and the reply.
    events: list[tuple[float, bytes]] = [(50.0, dp.arm())]
    events += [(50.0 + 300 * k, dp.servo_reset()) for k in range(1, 8)]
    t = 50.0 + dp.ARMING_HOLD_MS + 150
    events.append((t, NEW_FRAME))
    new = fw.simulate(events, t + 60, elf=build / "uno" / "uno.elf")
    assert new.replies()[0] == f"#READY {dp.PROTOCOL_NAME} {fingerprint.group(1)}"
    assert new.replies_between(t, t + 60) == ["Amg"]
    pitch = new.widths_us(fw.PINS["pitch"], t + 25, t + 60)
    assert pitch and all(abs(w - 1700) <= 2 for w in pitch), pitch
    others = {name: new.widths_us(fw.PINS[name], t + 25, t + 60) for name in ("roll", "throttle", "yaw")}
    assert all(w and all(abs(x - fw.neutral()[name]) <= 2 for x in w) for name, w in others.items()), others

    # The firmware built from the committed spec refuses the same frame as a bad direction (armed or not:
    # the parser rejects it before any state is consulted).
    fw.make("firmware-uno")
    old = fw.simulate([(50.0, NEW_FRAME)], 100)
    refused = old.replies_between(50, 100)
    assert refused[0] == dp.rejected_line(dp.ErrorKind.BAD_DIRECTION).decode().rstrip()
    assert not [r for r in refused if r.startswith("A")]  # the parser slides on over "1700": no frame in it
    pitch_old = old.widths_us(fw.PINS["pitch"], 75, 100)
    assert pitch_old and all(abs(w - fw.on_ground()["pitch"]) <= 2 for w in pitch_old)
