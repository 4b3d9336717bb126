"""The whole pipeline on runs of a packaged video's consecutive frames, and the laser-on count of any sequence.

A video run is a fixed 4:3 crop (half to all of the frame's height) of ``FRAMES`` consecutive frames at 320x240:
the scene's own motion, compression and noise from frame to frame, where vision_sequences.py jitters one still.
Target runs carry a shaded ball of a size the pilot fires at (``firing_sizes``) near the centre, drifting a pixel
or so a frame (a hovering drone's view); empty runs carry nothing. ``laser_frames`` replays the gate as the pilot
flies it: a frame whose gate is confirmed (the laser may be on) while the detection is not on the ball, or on a run
with no ball at all, with the centring and range conditions lifted for those (as if the drone had turned to face
what it saw).
"""

from __future__ import annotations

import dataclasses
import math

import cv2
import numpy as np
import packaged
import vision_imagery as vi
import vision_sequences as vs

from pilot.common.config import ControllerConfig, PilotConfig
from pilot.vision.detect import make_detector
from pilot.vision.gating import Gate

FRAMES = {"target": vs.TARGET_FRAMES, "empty": vs.NEGATIVE_FRAMES}


def _crop(rng: np.random.Generator, shape: tuple[int, ...]) -> tuple[int, int, int, int]:
    h, w = shape[:2]
    ch = int(min(h, w * 3 / 4) * rng.uniform(0.5, 1.0))
    cw = ch * 4 // 3
    return int(rng.integers(0, h - ch + 1)), int(rng.integers(0, w - cw + 1)), ch, cw


def video_runs(video: str, seed: int, targets: int, empty: int, config: PilotConfig | None = None
               ) -> list[vs.Sequence]:
    """``targets`` runs with a ball and ``empty`` runs without, each through a fresh ``make_detector``."""
    cfg = config or PilotConfig()
    rng = np.random.default_rng(seed)
    frames = packaged.frames(video)
    out: list[vs.Sequence] = []
    for kind, count in (("target", targets), ("empty", empty)):
        for _ in range(count):
            n = FRAMES[kind]
            start = int(rng.integers(0, len(frames) - n + 1))
            y, x, ch, cw = _crop(rng, frames[0].shape)
            det = make_detector(cfg)
            d = float(np.exp(rng.uniform(*np.log(vs.firing_sizes(cfg)))))
            cx, cy = vi.W / 2 + rng.uniform(-0.05, 0.05) * vi.W, vi.H / 2 + rng.uniform(-0.05, 0.05) * vi.H
            dets, truth = [], []
            for k in range(n):
                img = np.asarray(cv2.resize(frames[start + k][y : y + ch, x : x + cw], (vi.W, vi.H),
                                            interpolation=cv2.INTER_AREA), np.uint8)
                if kind == "target":
                    cx, cy = cx + float(rng.normal(0, 1.0)), cy + float(rng.normal(0, 1.0))
                    vi.shaded_ball(img, cx, cy, d, np.random.default_rng(seed * 1000 + len(out)))  # same shading
                    truth.append((cx, cy))
                dets.append(det.detect(img))
            out.append(vs.Sequence(kind, "video", tuple(dets), tuple(truth), d if kind == "target" else 0.0))
    return out


def laser_frames(seq: vs.Sequence, base: ControllerConfig | None = None) -> int:
    """Frames of ``seq`` in which the laser could be on without being on the target."""
    cfg = base or ControllerConfig()
    if seq.kind != "target":
        cfg = dataclasses.replace(cfg, fire_tolerance=1.0, fire_range_max_m=1e9)
    gate = Gate(cfg)
    wrong = 0
    for i, d in enumerate(seq.detections):
        gate.observe(d)
        if not gate.confirmed():
            continue
        if seq.kind != "target":
            wrong += 1
        else:
            tx, ty = seq.truth[i]
            wrong += math.hypot(d.cx - tx, d.cy - ty) > max(3.0, 0.3 * seq.size)
    return wrong
