"""The generated Rust is rustfmt's own output (with the crate's rustfmt.toml): `cargo fmt --check` on the shipped
crate, and `rustfmt --check` on crates generated from seeded variants of the spec whose name lengths and list sizes
move every spec-dependent line across rustfmt's width limits (names up to the 40-character limit, a single
command, the crc8 integrity mode)."""

from __future__ import annotations

import random
import string
import tempfile
from pathlib import Path
from typing import Any

import pytest
import targets_harness as t
import yaml

from generator.cli import main as generate

NAME_LIMIT = 40  # the spec's limit on a command's name (category prefix, "_", direction name)


def _name(rng: random.Random, length: int, index: int) -> str:
    """A snake_case name of about `length` characters, unique by its index."""
    text = "".join(rng.choice(string.ascii_lowercase + "_") for _ in range(max(0, length - 2)))
    return ("n" + text.strip("_").replace("__", "_") + str(index))[:length]


def variant(seed: int) -> str:
    """The shipped spec with random names, random subsets of its categories and directions, and on odd seeds crc8."""
    rng = random.Random(seed)
    spec: dict[str, Any] = yaml.safe_load((t.ROOT / "spec" / "drone.yaml").read_text(encoding="utf-8"))
    single = seed % 4 == 0
    codes = list(spec["categories"])
    kept = rng.sample(codes, 1 if single else rng.randint(1, len(codes)))
    categories = {}
    for ci, code in enumerate(kept):
        category = spec["categories"][code]
        category["name"] = _name(rng, rng.randint(3, 15), ci)
        prefix = len(category["name"]) + 1 if category.get("command_prefix") != "" else 0
        directions = list(category["directions"].items())
        chosen = rng.sample(directions, 1 if single else rng.randint(1, len(directions)))
        for di, (_, direction) in enumerate(chosen):
            direction["name"] = _name(rng, rng.randint(2, NAME_LIMIT - prefix), di)
        category["directions"] = dict(chosen)
        categories[code] = category
    spec["categories"] = categories
    if seed % 2:
        spec["frame"]["integrity"] = "crc8"
    return yaml.safe_dump(spec, sort_keys=False, allow_unicode=True)


def rustfmt_check(crate: Path) -> None:
    sources = sorted(map(str, crate.rglob("*.rs")))
    t.run(["rustfmt", "--check", "--edition", "2021", "--config-path", str(crate / "rustfmt.toml"), *sources])


def test_the_shipped_crate_is_rustfmt_clean() -> None:
    t.run(["cargo", "fmt", "--check"], cwd=t.CRATE)


@pytest.mark.parametrize("seed", range(8))
def test_crates_of_spec_variants_are_rustfmt_clean(seed: int) -> None:
    with tempfile.TemporaryDirectory(prefix="rustfmt_spec_") as tmp:
        spec = Path(tmp) / "drone.yaml"
        spec.write_text(variant(seed), encoding="utf-8")
        assert generate(["--spec", str(spec), "--out", str(Path(tmp) / "generated")]) == 0
        rustfmt_check(Path(tmp) / "generated" / "rust")
