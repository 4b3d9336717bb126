"""Safety by design against one corrupted byte (generator/safety.py): every pair of commands one byte apart whose
safety effects differ is found (checked against a brute force over the vectors' valid frames), printed by
`--check` and listed in the docs; the frames the pilot sends routinely have no valid one-byte neighbour."""

from __future__ import annotations

import contextlib
import json
import shutil
from pathlib import Path

import drone_protocol as dp
import protocol_harness as h

from generator.build import load_spec
from generator.safety import ROUTINE, free_of_neighbours, one_byte_neighbours, substitution_rates

SPEC = h.ROOT / "spec" / "drone.yaml"
EFFECTS = {c.direction.command: c.direction.safety or ROUTINE for c in load_spec(SPEC).commands}


def corruptions(frame: bytes) -> list[dp.Command]:
    """Every valid command one substituted byte makes of `frame`."""
    out = []
    for pos in range(len(frame)):
        for byte in range(256):
            other = frame[:pos] + bytes([byte]) + frame[pos + 1:]
            if other != frame:
                with contextlib.suppress(dp.ProtocolError):
                    out.append(dp.decode(other))
    return out


def test_the_pairs_are_exactly_what_a_brute_force_over_the_valid_vectors_finds() -> None:
    vectors = json.loads((h.ROOT / "generated" / "vectors.json").read_text())["vectors"]
    found = set()
    for v in (v for v in vectors if v["ok"]):
        for other in corruptions(bytes.fromhex(v["frame_hex"])):
            if EFFECTS[other.name.value] != EFFECTS[v["command"]]:
                found.add(frozenset((v["command"], other.name.value)))
    reported = {frozenset((n.a.direction.command, n.b.direction.command)) for n in one_byte_neighbours(load_spec(SPEC))}
    assert reported == found
    assert frozenset(("hold_altitude", "land")) in reported and frozenset(("laser_off", "laser_on")) in reported


def test_every_reported_example_is_two_valid_frames_one_byte_apart() -> None:
    for n in one_byte_neighbours(load_spec(SPEC)):
        a, b = n.example_a.encode(), n.example_b.encode()
        assert sum(x != y for x, y in zip(a, b, strict=True)) == 1
        assert (dp.decode(a).name.value, dp.decode(b).name.value) == (n.a.direction.command, n.b.direction.command)


def test_the_pilots_routine_frames_have_no_valid_one_byte_neighbour() -> None:
    """The keep-alive and neutral command (hold_altitude), laser_off and the status poll as the pilot sends them."""
    for frame in (dp.hold_altitude(), dp.laser_off()):
        assert {c.name for c in corruptions(frame)} == {dp.decode(frame).name}, frame  # only its other form
        assert free_of_neighbours(load_spec(SPEC), frame.decode())
    # the status poll, sent every tick while the pilot waits for a confirmation, has no valid neighbour at all
    assert not list(corruptions(dp.query_status())) and free_of_neighbours(load_spec(SPEC), dp.query_status().decode())
    # the seed's forms are still accepted, and are exposed: one byte from a landing, and from the laser on
    assert {c.name.value for c in corruptions(dp.hold_altitude(0))} >= {"land", "arm", "disarm"}
    assert "laser_on" in {c.name.value for c in corruptions(dp.laser_off(0))}


def test_check_prints_every_pair_and_the_docs_list_them(tmp_path: Path) -> None:
    run = h.generate("--check", "--spec", SPEC, "--out", h.ROOT / "generated")
    pairs = one_byte_neighbours(load_spec(SPEC))
    lines = [line for line in run.stdout.splitlines() if line.startswith("safety: ")]
    assert len(lines) == len(pairs) + 1
    assert "is0000 (hold_altitude, routine) is one byte from il0000 (land)" in run.stdout
    assert lines[-1].startswith(f"safety: {len(pairs)} pairs") and "none is caught" in lines[-1]
    docs = (h.ROOT / "generated" / "docs" / "protocol.md").read_text(encoding="utf-8")
    for n in pairs:
        assert f"| `{n.example_a}` | {n.label(n.a)} | `{n.example_b}` | {n.label(n.b)} |" in docs


def test_in_crc8_mode_every_pair_is_reported_caught(tmp_path: Path) -> None:
    text = SPEC.read_text(encoding="utf-8")
    (tmp_path / "drone.yaml").write_text(h.edit(text, "  integrity: none\n", "  integrity: crc8\n"), encoding="utf-8")
    assert h.generate("--spec", tmp_path / "drone.yaml", "--out", tmp_path / "out").code == 0
    run = h.generate("--check", "--spec", tmp_path / "drone.yaml", "--out", tmp_path / "out")
    lines = [line for line in run.stdout.splitlines() if line.startswith("safety: ")]
    assert run.code == 0 and all(line.endswith("crc8 catches it") for line in lines[:-1]) and len(lines) > 5
    assert "each caught by crc8" in lines[-1]


def test_an_unknown_safety_effect_is_one_clear_error(tmp_path: Path) -> None:
    text = SPEC.read_text(encoding="utf-8")
    (tmp_path / "drone.yaml").write_text(h.edit(text, "        safety: land\n", "        safety: lands\n"),
                                         encoding="utf-8")
    run = h.generate("--spec", tmp_path / "drone.yaml", "--out", tmp_path / "out")
    assert run.code == 2 and "unknown safety effect 'lands'" in run.stderr and "did you mean 'land'?" in run.stderr
    assert not (tmp_path / "out").exists()


def test_a_spec_without_an_integrity_mode_gets_crc8_and_an_old_output_stops_it(tmp_path: Path) -> None:
    """crc8 is the default of new specs (bench/lossy/RESULTS.md); a spec that relied on the old default (none)
    is not moved to crc8 unnoticed over its earlier output: the breaking-change check names the mode."""
    text = h.edit(SPEC.read_text(encoding="utf-8"), "  integrity: none\n", "")
    (tmp_path / "drone.yaml").write_text(text, encoding="utf-8")
    assert h.generate("--spec", tmp_path / "drone.yaml", "--out", tmp_path / "new").code == 0
    assert '"integrity": "crc8"' in (tmp_path / "new" / "vectors.json").read_text(encoding="utf-8")
    shutil.copytree(h.ROOT / "generated", tmp_path / "old")
    run = h.generate("--spec", tmp_path / "drone.yaml", "--out", tmp_path / "old")
    assert run.code == 2 and "frame.integrity: 'none' -> 'crc8'" in run.stderr


def test_the_exact_substitution_rate_matches_its_first_order_term() -> None:
    """is0000's four one-byte neighbours (arm, disarm, first_test, land) dominate its chance, at 1 % per byte, of
    arriving with another safety effect: 4 q (1-q)^5 / 255, plus two-byte terms ~1000 times smaller."""
    spec, q = load_spec(SPEC), 0.01
    first_order = 4 * q * (1 - q) ** 5 / 255
    other, hazard = substitution_rates(spec, b"is0000", False, q)
    assert first_order <= hazard < first_order * 1.01 and other >= hazard
    assert substitution_rates(spec, dp.hold_altitude(), False, q)[1] < first_order / 10_000
    assert substitution_rates(spec, dp.hold_altitude(), True, q)[1] < substitution_rates(spec, b"is0000", True, q)[1]
