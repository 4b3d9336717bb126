"""The generated Arduino library as an Arduino IDE user meets it: installed into a fresh sketchbook and every
example, the drone firmware and the README's sketch built by Debian's arduino-builder (the builder of IDE 1.8),
for the Uno and the Mega 2560. A rejected library or a failing example fails the test.

Nothing is cached across runs: each run installs into a new temporary sketchbook and builds from scratch (the
core is shared between the builds of one board within the run only)."""

from __future__ import annotations

import re
import shutil
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import drone_protocol as dp
import fwsupport as fw
import pytest
import sketchbook as sb

from generator.build import load_spec

pytestmark = pytest.mark.skipif(shutil.which("arduino-builder") is None,
                                reason="arduino-builder missing: `make deps` installs it")
README = fw.ROOT / "README.md"
BOARDS = ("uno", "mega")


def readme_sketch() -> str:
    """The C++ block of the README's "Using the Arduino library" section."""
    text = README.read_text(encoding="utf-8")
    section = text.split("### Using the Arduino library", 1)[1]
    match = re.search(r"```cpp\n(.*?)```", section, re.S)
    assert match, "the README's Arduino section has no ```cpp block"
    return match.group(1)


def sketch_copy(source: Path, name: str, where: Path, edit: Callable[[Path], None] | None = None) -> Path:
    """A copy of the sketch folder `source` as where/name/name.ino, as a user would save it."""
    folder = where / name
    shutil.copytree(source, folder)
    (ino,) = folder.glob("*.ino")
    ino.rename(folder / f"{name}.ino")
    if edit is not None:
        edit(folder)
    return folder / f"{name}.ino"


def enable_ppm(folder: Path) -> None:
    config = folder / "drone_config.h"
    text = config.read_text(encoding="utf-8")
    assert text.count("// #define DRONE_PPM\n") == 1, "drone_config.h no longer documents the PPM switch"
    config.write_text(text.replace("// #define DRONE_PPM\n", "#define DRONE_PPM\n"), encoding="utf-8")


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> dict[tuple[str, str], sb.Build]:
    root = tmp_path_factory.mktemp("ide")
    book = root / "Arduino"
    library = sb.install(book)
    sketches = {ex.name: ex / f"{ex.name}.ino" for ex in sorted((library / "examples").iterdir())}
    (book / "ReadmeSketch").mkdir()
    (book / "ReadmeSketch" / "ReadmeSketch.ino").write_text(readme_sketch(), encoding="utf-8")
    sketches["ReadmeSketch"] = book / "ReadmeSketch" / "ReadmeSketch.ino"
    sketches["DroneFirmwarePpm"] = sketch_copy(library / "examples" / sb.FIRMWARE_EXAMPLE, "DroneFirmwarePpm", book,
                                               enable_ppm)
    jobs = [(name, board) for board in BOARDS for name in sketches if not (board == "mega" and name.endswith("Ppm"))]

    def one(job: tuple[str, str]) -> sb.Build:
        name, board = job
        return sb.build(sketches[name], book, root / "build" / board / name, board, cache=root / "cache" / board)

    # Two at a time (the machine has two cores); the first build of each board fills its core cache.
    with ThreadPoolExecutor(max_workers=2) as pool:
        firsts = [j for j in jobs if j[0] == sb.FIRMWARE_EXAMPLE]
        results = dict(zip(firsts, pool.map(one, firsts), strict=True))
        rest = [j for j in jobs if j not in results]
        results.update(zip(rest, pool.map(one, rest), strict=True))
    return results


def test_every_example_builds_for_uno_and_mega(built: dict[tuple[str, str], sb.Build]) -> None:
    examples = {name for name, _ in built} - {"ReadmeSketch", "DroneFirmwarePpm"}
    assert {"DecodeFrames", "ServosAndLaser", sb.FIRMWARE_EXAMPLE} <= examples
    for board in BOARDS:
        for name in examples:
            b = built[(name, board)]
            assert b.flash > 0 and b.ram > 0, (name, board)


def test_the_ide_accepts_the_library_from_the_sketchbook_without_a_warning(
        built: dict[tuple[str, str], sb.Build]) -> None:
    version = sb.library_version()
    assert version == f"{dp.PROTOCOL_VERSION}.0.0"
    for (name, board), b in built.items():
        assert re.search(rf"Using library DroneProtocol at version {re.escape(version)} in folder: \S+/Arduino/"
                         r"libraries/DroneProtocol", b.output), (name, board)
        assert not re.search(r"(?im)^warning|warning:|invalid|not valid", b.output), (name, board, b.output[-2000:])


def test_the_readme_sketch_builds(built: dict[tuple[str, str], sb.Build]) -> None:
    assert "void setup()" in readme_sketch() and "void loop()" in readme_sketch()
    assert built[("ReadmeSketch", "uno")].flash > 0


def test_the_documented_define_selects_the_ppm_build(built: dict[tuple[str, str], sb.Build],
                                                     tmp_path_factory: pytest.TempPathFactory) -> None:
    parallel, ppm = built[(sb.FIRMWARE_EXAMPLE, "uno")], built[("DroneFirmwarePpm", "uno")]
    assert ppm.flash != parallel.flash
    # The IDE's PPM binary in simavr: one PPM-sum train on the spec's PPM pin, the other RC pins silent.
    fw.make("firmware-sim")
    result = fw.simulate([], 200, elf=ppm.elf)
    wiring = load_spec(fw.ROOT / "spec" / "drone.yaml").wiring
    rc_channels = len(wiring.rc_inputs)
    # 200 ms of 22.5 ms frames, each one separator pulse per channel plus the closing one.
    assert len(result.pulses.get(wiring.ppm.pin, [])) >= 8 * (rc_channels + 1), "no PPM train on the PPM pin"
    for pin in wiring.rc_inputs:
        if pin.pin != wiring.ppm.pin:
            assert pin.pin not in result.pulses, f"{pin.name} pulses in the PPM build"


def test_a_library_the_ide_rejects_fails_the_build(tmp_path: Path) -> None:
    """The check above would have caught issue 10: a `//` line in library.properties."""
    book = tmp_path / "Arduino"
    library = sb.install(book)
    props = library / "library.properties"
    props.write_text("// a C++ comment\n" + props.read_text(encoding="utf-8"), encoding="utf-8")
    with pytest.raises(sb.SketchbookError, match="invalid"):
        sb.build(library / "examples" / "DecodeFrames" / "DecodeFrames.ino", book, tmp_path / "build")
