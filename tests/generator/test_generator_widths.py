"""C++ and Python agree on every constant: a compiled program prints each number DroneProtocol.h declares, and
each equals the model's value and the Python module's, for the shipped spec and for random valid specs. The
C++ types are the ones generator/widths.py declares (the template prints them from that table), and the
largest command count the table allows still compiles and decodes."""

from __future__ import annotations

import re
import subprocess
import tempfile
from pathlib import Path
from types import ModuleType
from typing import Any

import protocol_harness as h
import yaml
from hypothesis import HealthCheck, given, settings
from test_generator_hostile_specs import many_commands
from test_generator_random_specs import load_module, random_specs

from generator.build import load_spec
from generator.model import Spec
from generator.names import pascal
from generator.widths import CTYPES, SCALARS, constants

CPP_FLAGS = ("-std=c++11", "-Wall", "-Wextra", "-Werror", "-Wconversion", "-O0")


def printer(spec: Spec, names: list[str]) -> str:
    """A C++ program printing the named constants and every command's numbers."""
    lines = [f'  printf("%s %lld\\n", "{name}", static_cast<long long>({name}));' for name in names]
    return f"""#include <{pascal(spec.name)}.h>
#include <stdio.h>
using namespace {spec.name};
using namespace {spec.name}::detail;
int main() {{
{chr(10).join(lines)}
  for (uint16_t i = 0; i < COMMAND_COUNT; ++i) {{
    const CommandId id = static_cast<CommandId>(i);
    const CommandInfo c = command_info(id);
    printf("command %s %u %u %u %u\\n", command_name(id), static_cast<unsigned>(c.min), static_cast<unsigned>(c.max),
           static_cast<unsigned>(c.default_value), static_cast<unsigned>(c.has_default));
  }}
  return 0;
}}
"""


def python_value(p: ModuleType, name: str, spec: Spec) -> int | None:
    """The Python module's value of a C++ constant, or None where Python has no such constant."""
    for c in spec.channels:
        for suffix, attr in (("MIN", "minimum"), ("MAX", "maximum"), ("MEDIAN", "median"), ("LOW", "low"),
                             ("HIGH", "high")):
            if name == f"{c.name.upper()}_{suffix}":
                return int(getattr(p.CHANNELS[c.name], attr))
    for s in spec.servos:
        for suffix, attr in (("MIN", "minimum"), ("MAX", "maximum"), ("DEFAULT", "default")):
            if name == f"SERVO_{s.name.upper()}_{suffix}":
                return int(getattr(p.SERVOS[s.name], attr))
    counts = {"COMMAND_COUNT": len(p.COMMANDS), "CATEGORY_COUNT": len(p.Category), "CHANNEL_COUNT": len(p.CHANNELS)}
    if name in counts:
        return counts[name]
    value = getattr(p, name, None)
    return value if isinstance(value, int) else None


def check_generated(spec_path: Path, out: Path, p: ModuleType) -> None:
    spec = load_spec(spec_path)
    include = out / "arduino" / pascal(spec.name) / "src"
    header = h.header_text(include)
    # the header declares each table constant with the table's type
    for name, (ctype, _, _) in SCALARS.items():
        found = re.search(rf"constexpr (\w+) {name} =", header)
        assert found is None or found[1] == ctype.name, (name, found and found[1], ctype.name)
    for c in constants(spec):
        if c.name.endswith(("_MIN", "_MAX", "_MEDIAN", "_LOW", "_HIGH", "_DEFAULT")):
            assert re.search(rf"constexpr {c.ctype.name} {c.name} =", header), c.name
    # the ones the template declares (a constant the table bounds ahead of the template, e.g. LANDING_MS, is not)
    declared = [c.name for c in constants(spec) if re.search(rf"constexpr \w+ {c.name} =", header)]
    assert {"COMMAND_COUNT", "BAUD", "FRAME_LENGTH", "REPLY_MAX_LENGTH"} <= set(declared)
    exe = h.compile_cpp(printer(spec, declared), "constants", include=include, flags=CPP_FLAGS)
    lines = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60, check=True).stdout.splitlines()
    printed = dict(line.split(" ", 1) for line in lines if not line.startswith("command "))
    for c in constants(spec):
        if c.name not in printed:
            continue
        assert int(printed[c.name]) == c.value, (c.name, printed[c.name], c.value)
        python = python_value(p, c.name, spec)
        assert python is None or python == c.value, (c.name, python, c.value)
    commands = [line.split()[1:] for line in lines if line.startswith("command ")]
    assert len(commands) == len(p.COMMANDS)
    for name, lo, hi, default, has_default in commands:
        cmd = p.COMMANDS[name]
        assert (int(lo), int(hi)) == (cmd.minimum, cmd.maximum), name
        assert (cmd.default if cmd.default is not None else 0, cmd.default is not None) == \
            (int(default), has_default == "1"), name


def test_cpp_and_python_constants_agree_for_the_shipped_spec() -> None:
    import drone_protocol

    check_generated(h.SPEC, h.GENERATED, drone_protocol)


@settings(max_examples=5, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(random_specs())
def test_cpp_and_python_constants_agree_for_random_valid_specs(spec: dict[str, Any]) -> None:
    with tempfile.TemporaryDirectory(prefix="widths_") as tmp:
        generate_and_check(spec, Path(tmp))


def generate_and_check(spec: dict[str, Any], root: Path) -> None:
    path, out = root / "drone.yaml", root / "generated"
    path.write_text(yaml.safe_dump(spec, sort_keys=False), encoding="utf-8")
    run = h.generate("--spec", path, "--out", out)
    assert run.code == 0, run.stderr
    p = load_module(out / "python" / "drone_protocol", f"drone_protocol_widths_{abs(hash(path.read_text()))}")
    check_generated(path, out, p)


def test_more_commands_than_an_8_bit_index_holds_compile_and_decode(tmp_path: Path) -> None:
    """Past 254 commands the C++ CommandIndex grows to 16 bits (which every spec fits: 94 x 94 codes at most)."""
    assert CTYPES["command_index"].maximum >= 94 * 94
    spec: dict[str, Any] = yaml.safe_load(h.spec_text())
    many_commands(300)(spec)
    generate_and_check(spec, tmp_path)
