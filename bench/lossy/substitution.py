"""One corrupted byte, counted exactly (``python -m bench.lossy.substitution``): for each frame the pilot sends
routinely, in its old and new form, with frame.integrity none and crc8, the probability that a frame whose bytes
are each replaced, with probability q, by another byte (uniformly one of the 255 others) arrives as another
valid command, and as one whose safety effect differs (spec ``safety:``). Exact: every valid frame of the
spec is a target at its Hamming distance. Writes its section of bench/lossy/RESULTS.md (between the markers).
"""

from __future__ import annotations

import argparse
import textwrap
from pathlib import Path

import drone_protocol as dp

from generator.build import load_spec
from generator.filters import one_in
from generator.safety import substitution_rates

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
BEGIN, END = "<!-- substitution: begin -->", "<!-- substitution: end -->"
FRAMES = ((b"is0000", "hold_altitude, the seed's form: the keep-alive before"),
          (dp.hold_altitude(), "hold_altitude as the pilot sends it (keep-alive, neutral)"),
          (b"lf0000", "laser_off, the seed's form"),
          (dp.laser_off(), "laser_off as the pilot sends it"),
          (dp.move_forward(1600), "a move (routine)"),
          (b"ia0000", "arm"))

SPEC = load_spec(REPO / "spec" / "drone.yaml")


def rates(frame: bytes, crc8: bool, q: float) -> tuple[float, float]:
    """(P another command, P another safety effect) for one frame: generator/safety.py's exact count."""
    return substitution_rates(SPEC, frame, crc8, q)


def decision(hazard: dict[tuple[bytes, bool], float], q: float) -> str:
    """The decision on crc8 for new specs, with the figures it rests on."""
    bits = 1 + dp.DATA_BITS + dp.STOP_BITS + (0 if dp.PARITY == "none" else 1)

    def ms(n: int) -> float:
        return n * bits * 1000 / dp.BAUD

    keep = dp.hold_altitude()
    return "\n".join(textwrap.wrap(
        f"**Decision: `frame.integrity: crc8` is the default of new specs** (a spec without the key; a spec that "
        f"relied on the old default and is generated over its earlier output is stopped by the generator's check "
        f"of breaking changes, which names the integrity mode). At {q:.0%} substitution, without a check the "
        f"seed's keep-alive `is0000` became a command "
        f"with another safety effect {one_in(hazard[b'is0000', False])} frames, and the pilot's keep-alive "
        f"`{keep.decode()}` still does so {one_in(hazard[keep, False])}; with crc8 it is "
        f"{one_in(hazard[keep, True])}, and every single corrupted byte is caught. The cost: 2 bytes more per "
        f"frame ({dp.FRAME_LENGTH + 2} instead of {dp.FRAME_LENGTH}: {ms(dp.FRAME_LENGTH + 2):.2f} ms instead of "
        f"{ms(dp.FRAME_LENGTH):.2f} ms at {dp.BAUD} baud) and 3 per reply line; in flight (the table above) crc8 "
        f"completed and ended safe as many flights as none at every rate. This project's own spec keeps "
        f"`integrity: none`, written out: its link is USB, which checks its own packets, and it stays "
        f"byte-compatible with the seed.", 116))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rate", type=float, default=0.01, help="substitution probability per byte (default 0.01)")
    ap.add_argument("--no-write", action="store_true")
    opts = ap.parse_args()
    rows = []
    found: dict[tuple[bytes, bool], float] = {}
    for frame, what in FRAMES:
        for crc8 in (False, True):
            other, hazard = rates(frame, crc8, opts.rate)
            found[frame, crc8] = hazard
            rows.append(f"| `{frame.decode()}` | {what} | {'crc8' if crc8 else 'none'} | {one_in(other)} | "
                        f"{one_in(hazard)} |")
    text = "\n".join([
        BEGIN,
        f"## One corrupted byte (python -m bench.lossy.substitution; {opts.rate:.0%} of bytes substituted)",
        "",
        "Exact probability, per frame sent, that it arrives as another valid command, and as one whose safety",
        "effect (spec `safety:`) differs: the sum over every valid frame of another command (with its check in",
        "crc8 mode) at Hamming distance d of q^d (1-q)^(n-d) / 255^d.",
        "",
        "| frame | what | integrity | another command | another safety effect |",
        "|---|---|---|---|---|",
        *rows,
        "",
        decision(found, opts.rate),
        END,
    ])
    print(text)
    if not opts.no_write:
        results = HERE / "RESULTS.md"
        old = results.read_text(encoding="utf-8")
        kept = old.split(BEGIN)[0].rstrip("\n") + "\n\n" if BEGIN in old else old.rstrip("\n") + "\n\n"
        after = old.split(END, 1)[1].lstrip("\n") if END in old else ""
        results.write_text(kept + text + "\n" + (("\n" + after) if after else ""), encoding="utf-8")


if __name__ == "__main__":
    main()
