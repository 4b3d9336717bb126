"""Random valid specs: the generator accepts them, and the Python and C++ it prints agree with each other and with
the vectors it prints, on every vector and on frames built from the spec's own codes."""

from __future__ import annotations

import hashlib
import importlib.util
import json
import random
import subprocess
import sys
import tempfile
from pathlib import Path
from types import ModuleType
from typing import Any

import protocol_harness as h
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

# Printable ASCII, without the two characters that break generated string literals today (see
# test_generator_names_and_codes.py): the subject here is the codecs, not the escaping.
PRINTABLE = [chr(c) for c in range(0x21, 0x7F) if chr(c) not in "\"\\"]
CATEGORY_CODES = [c for c in PRINTABLE if not c.isdigit()]
WORDS = ["alpha", "bravo", "charlie", "delta", "echo", "foxtrot", "golf", "hotel", "kilo", "lima"]
CHANNELS = ["yaw", "roll", "pitch", "throttle"]


@st.composite
def random_specs(draw: st.DrawFn) -> dict[str, Any]:
    spec: dict[str, Any] = yaml.safe_load(h.spec_text())
    fields: dict[str, Any] = {k: v for k, v in spec["fields"].items() if k in ("speed", "zero")}
    categories: dict[str, Any] = {}
    codes = draw(st.lists(st.sampled_from(CATEGORY_CODES), min_size=1, max_size=6, unique=True))
    for ci, code in enumerate(codes):
        directions: dict[str, Any] = {}
        for di, dcode in enumerate(draw(st.lists(st.sampled_from(PRINTABLE), min_size=1, max_size=6, unique=True))):
            direction: dict[str, Any] = {"name": f"{draw(st.sampled_from(WORDS))}{di}", "description": "A move"}
            kind = draw(st.sampled_from(["range", "zero", "speed"]))
            if kind == "range":
                lo = draw(st.integers(0, 9999))
                hi = draw(st.integers(lo, min(9999, lo + draw(st.sampled_from([0, 9, 200, 9999])))))
                field: dict[str, Any] = {"width": 4, "unit": "u", "range": [lo, hi], "parameter": "amount",
                                         "description": "An amount"}
                if draw(st.booleans()):
                    field["default"] = draw(st.integers(lo, hi))
                fields[f"f{ci}_{di}"] = field
                direction["field"] = f"f{ci}_{di}"
            elif kind == "zero":
                direction["field"] = "zero"
            else:
                direction["field"] = "speed"
                direction["channel"] = draw(st.sampled_from(CHANNELS))
                direction["default"] = draw(st.sampled_from(["low", "median", "high"]))
            directions[dcode] = direction
        categories[code] = {"name": f"{draw(st.sampled_from(WORDS))}_c{ci}", "hardware": "Something",
                            "description": "A category", "directions": directions}
    spec["fields"] = fields
    spec["categories"] = categories
    return spec


def load_module(path: Path, name: str) -> ModuleType:
    """Import a generated drone_protocol package under another name (the installed one stays untouched)."""
    module_spec = importlib.util.spec_from_file_location(name, path / "__init__.py")
    assert module_spec is not None and module_spec.loader is not None
    module = importlib.util.module_from_spec(module_spec)
    sys.modules[name] = module  # dataclasses look their module up while the class is built
    try:
        module_spec.loader.exec_module(module)
    finally:
        del sys.modules[name]
    return module


def python_result(p: Any, frame: bytes) -> str:
    try:
        cmd = p.decode(frame)
    except p.ProtocolError as exc:
        return f"err {exc.kind.name.lower()}"
    return f"ok {cmd.name} {ord(cmd.category.value)} {ord(cmd.direction.value)} {cmd.value}"


def frames_from(spec: dict[str, Any], rng: random.Random, count: int) -> list[bytes]:
    codes = [(c, d) for c, cat in spec["categories"].items() for d in cat["directions"]]
    alphabet = sorted({ord(c) for pair in codes for c in pair} | set(b"0123456789"))
    out = []
    for i in range(count):
        c, d = rng.choice(codes)
        if i % 3 == 0:
            out.append(f"{c}{d}{rng.randrange(10_000):04d}".encode())
        elif i % 3 == 1:
            out.append(bytes(rng.choice(alphabet) for _ in range(6)))
        else:
            frame = bytearray(f"{c}{d}{rng.randrange(10_000):04d}".encode())
            frame[rng.randrange(6)] = rng.randrange(256)
            out.append(bytes(frame))
    return out


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(random_specs())
def test_for_any_valid_spec_python_and_cpp_agree(spec: dict[str, Any]) -> None:
    with tempfile.TemporaryDirectory(prefix="random_spec_") as tmp:
        check_spec(spec, Path(tmp))


def check_spec(spec: dict[str, Any], root: Path) -> None:
    text = yaml.safe_dump(spec, sort_keys=False, allow_unicode=True)
    key = hashlib.sha256(text.encode()).hexdigest()[:12]
    spec_path, out = root / "drone.yaml", root / "generated"
    spec_path.write_text(text, encoding="utf-8")
    run = h.generate("--spec", spec_path, "--out", out)
    assert run.code == 0, run.stderr

    p = load_module(out / "python" / "drone_protocol", f"drone_protocol_random_{key}")
    vectors = json.loads((out / "vectors.json").read_text())["vectors"]
    frames = [bytes.fromhex(v["frame_hex"]) for v in vectors] + frames_from(spec, random.Random(key), 3000)
    python = [python_result(p, f) for f in frames]
    expected = [f"ok {v['command']} {ord(v['category'])} {ord(v['direction'])} {v['value']}" if v["ok"]
                else f"err {v['error']}" for v in vectors]
    assert python[:len(vectors)] == expected

    driver = root / "driver"
    build = subprocess.run(["g++", "-std=c++11", "-Wall", "-Wextra", "-Werror", "-O0",
                            f"-I{out / 'arduino' / 'DroneProtocol' / 'src'}", str(h.CPP_DIR / "protocol_driver.cpp"),
                            "-o", str(driver)], capture_output=True, text=True, timeout=120)
    assert build.returncode == 0, build.stderr
    proc = subprocess.run([str(driver), "decode"], input="".join(f.hex() + "\n" for f in frames),
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines() == python
