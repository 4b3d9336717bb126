"""ArUco against its goals on the held-out sources (``PYTHONPATH=.:bench/vision .venv/bin/python
bench/vision/aruco_goals.py``, figures in RESULTS.md): markers 24-120 px clean, motion-blurred and with one corner
covered (``vision_imagery.CORNER_SHARE`` of the black square), and the share of empty and distractor views with a
detection, on the held-out photos (scikit-image's) and the bench photos (avr-libc's): with the default budget on
this (shared) machine's clock, and unbounded (the budget's clock frozen: what the detector can read).
"""

from __future__ import annotations

import sys

import vision_eval as ve
import vision_imagery as vi

from pilot.vision.aruco import ArucoMarkerDetector

CONDITIONS = ("clean", "motion_blur", "corner")
THRESHOLD = 0.6  # controller.acquire_confidence


def main(argv: list[str] | None = None) -> int:
    args = ve.counts_args(__doc__, argv, markers=(200, "markers per condition and source"),
                          empty=(500, "empty views per source"), seed=(61, "seed"))
    print("| source | budget | " + " | ".join(CONDITIONS) + " | empty views detected | distractor views detected |")
    print("|---|---|" + "---|" * (len(CONDITIONS) + 2))
    for k, (name, split) in enumerate((("held-out", vi.HELD_OUT), ("bench", vi.BENCH))):
        views = ve.samples(split, args.seed + k, args.markers, args.empty, args.empty // 10, "marker", (24.0, 120.0),
                           CONDITIONS)
        for label, clock in (("12.5 ms", None), ("unbounded", lambda: 0.0)):
            records = ve.run(ArucoMarkerDetector(clock=clock).candidates, views)
            rows = {r.group: r.rate for r in ve.target_rows(records, THRESHOLD, 0)}
            empty = ve.false_rows(records, THRESHOLD, "empty")[-1]
            dis = ve.false_rows(records, THRESHOLD, "distractor")[-1]
            print(f"| {name} | {label} | " + " | ".join(f"{rows[c]:.1%}" for c in CONDITIONS) +
                  f" | {empty.rate:.2%} of {empty.n} | {dis.rate:.2%} of {dis.n} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
