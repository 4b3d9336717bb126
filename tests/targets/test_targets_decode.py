"""decode() of the C and Rust targets against the Python codec on every conformance vector and a large seeded
sample of near-valid inputs of every length: same command and value, or the same error kind."""

from __future__ import annotations

import json
import random
import subprocess
import sys

import drone_protocol as p
import targets_harness as t

SAMPLE_SIZE = 100_000


def drivers() -> dict[str, list[str]]:
    """Every language's decode driver; the first is the reference."""
    c = t.BUILD / "decode_driver_c"
    t.BUILD.mkdir(parents=True, exist_ok=True)
    t.run(["gcc", *t.CFLAGS, f"-I{t.C_DIR}", str(t.DRIVERS / "decode_driver.c"), *map(str, t.c_sources()),
           "-o", str(c)])
    return {"python": [sys.executable, str(t.DRIVERS / "decode_driver.py")], "c": [str(c)],
            "rust": [str(t.rustc_program(t.DRIVERS / "decode_driver.rs", "decode_driver_rs"))]}


def sample(seed: int) -> list[bytes]:
    """Inputs biased toward almost-valid frames, where codecs are most likely to differ."""
    rng = random.Random(seed)
    specs = list(p.COMMANDS.values())
    prefixes = [s.prefix for s in specs]
    alphabet = bytes(sorted(set(b"".join(prefixes) + b"0123456789\x00 -\x7f\xff")))
    out = []
    for i in range(SAMPLE_SIZE):
        spec = rng.choice(specs)
        style = i % 5
        if style == 0:
            frame = rng.randbytes(rng.choice((p.FRAME_LENGTH, p.FRAME_LENGTH, rng.randrange(12))))
        elif style == 1:  # any value, in range or not
            frame = spec.prefix + b"%0*d" % (p.VALUE_WIDTH, rng.randrange(10 ** p.VALUE_WIDTH))
        elif style == 2:  # a valid frame with one byte replaced
            changed = bytearray(p.encode(spec.category, spec.direction, rng.randint(spec.minimum, spec.maximum)))
            changed[rng.randrange(p.FRAME_LENGTH)] = rng.randrange(256)
            frame = bytes(changed)
        elif style == 3:  # the protocol's own alphabet
            frame = bytes(rng.choice(alphabet) for _ in range(p.FRAME_LENGTH))
        else:  # one category's first byte with another's direction
            frame = spec.prefix[:1] + rng.choice(prefixes)[1:] + b"%0*d" % (p.VALUE_WIDTH, spec.maximum)
        out.append(frame)
    return out


def test_c_and_rust_decode_like_python_on_the_vectors_and_a_large_sample() -> None:
    vectors = json.loads((t.GENERATED / "vectors.json").read_text())["vectors"]
    frames = [bytes.fromhex(v["frame_hex"]) for v in vectors] + sample(20261123)
    stdin = "".join(f.hex() + "\n" for f in frames)
    outputs = {language: subprocess.run(cmd, input=stdin, capture_output=True, text=True, timeout=120,
                                        check=True).stdout.splitlines() for language, cmd in drivers().items()}
    expected = outputs["python"]
    for language, got in outputs.items():
        differ = [(f, a, b) for f, a, b in zip(frames, got, expected, strict=True) if a != b]
        assert differ == [], f"{language}: {len(differ)} inputs decode differently from python, e.g. {differ[:5]}"
    kinds = {r.split()[1] if r.startswith("err") else "ok" for r in expected}
    assert kinds >= {"ok", "bad_category", "bad_direction", "bad_digit", "out_of_range", "too_short", "too_long"}
