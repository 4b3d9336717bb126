"""The simpler colour-ball detector (pilot/vision/ball.py) against the rule-grown one (pilot/vision/hsv/) on the
held-out sources (``PYTHONPATH=.:bench/vision .venv/bin/python bench/vision/simple_vs_rules.py``, figures in
RESULTS.md): recall per condition for balls from 16 px, and the share of empty and distractor views with a
detection at the acquisition threshold. The budget's clock is frozen: this compares what each detector sees.
"""

from __future__ import annotations

import sys

import vision_eval as ve
import vision_imagery as vi

import pilot.vision.budget as budget
from pilot.vision.ball import SimpleBallDetector
from pilot.vision.hsv.detector import HsvBlobDetector

THRESHOLD = 0.6  # controller.acquire_confidence


def main(argv: list[str] | None = None) -> int:
    args = ve.counts_args(__doc__, argv, views=(100, "views per condition and source"),
                          empty=(500, "empty views per source"), seed=(71, "seed"))
    budget.CLOCK = lambda: 0.0
    print("| source | detector | " + " | ".join(vi.CONDITIONS) + " | empty | distractor |")
    print("|---|---|" + "---|" * (len(vi.CONDITIONS) + 2))
    for k, (name, split) in enumerate((("held-out", vi.HELD_OUT), ("bench", vi.BENCH))):
        views = ve.samples(split, args.seed + k, args.views, args.empty, args.empty // 5, "ball", (10.0, 120.0),
                           vi.CONDITIONS)
        for label, det in (("rules (hsv/)", HsvBlobDetector()), ("simple (ball.py)", SimpleBallDetector())):
            records = ve.run(det.candidates, views)
            rows = {r.group: r.rate for r in ve.target_rows(records, THRESHOLD, 16.0)}
            empty = ve.false_rows(records, THRESHOLD, "empty")[-1].rate
            dis = ve.false_rows(records, THRESHOLD, "distractor")[-1].rate
            print(f"| {name} | {label} | " + " | ".join(f"{rows.get(c, float('nan')):.1%}" for c in vi.CONDITIONS)
                  + f" | {empty:.2%} | {dis:.2%} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
