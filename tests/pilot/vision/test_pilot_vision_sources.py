"""bench/vision's source-separated evaluation (packaged.py, sources_seq.py): a packaged video's frames named and
loaded as stills, the split kept by source, and the laser-on count replayed through the gate."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import cv2
import numpy as np
import packaged as pk
import pytest
import sources_seq as sq
import vision_imagery as vi
import vision_sequences as vs

from pilot.vision.detection import Detection


def _video(path: Path, frames: int) -> None:
    out = cv2.VideoWriter(str(path), cv2.VideoWriter.fourcc(*"MJPG"), 10.0, (64, 48))
    for k in range(frames):
        out.write(np.full((48, 64, 3), 10 * k, np.uint8))
    out.release()


def test_a_packaged_videos_frames_are_stills_named_by_index(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _video(tmp_path / "clip.avi", 25)
    monkeypatch.setattr(pk, "OPENCV_DIR", tmp_path)
    pk.frames.cache_clear()
    try:
        names = pk.video_frames("opencv-doc:clip.avi")
        assert names == ("opencv-doc:clip.avi@0", "opencv-doc:clip.avi@10", "opencv-doc:clip.avi@20")
        still = vi.photo.__wrapped__(names[2])  # the view maker's loader, not its cache
        assert still.shape == (48, 64, 3) and abs(int(still.mean()) - 200) <= 3
        with pytest.raises(FileNotFoundError, match="opencv-doc"):
            pk.frames("opencv-doc:missing.avi")
    finally:
        pk.frames.cache_clear()


def test_every_source_is_tuning_or_held_out_and_no_still_is_in_two() -> None:
    assert {s.split for s in pk.SOURCES} == {"tuning", "held-out"}
    assert sum(s.split == "held-out" for s in pk.SOURCES) >= 3 and len(pk.SOURCES) >= 5
    stills = [n for s in pk.SOURCES for n in (*s.photos, *s.videos, *s.distractors)]
    assert len(stills) == len(set(stills))
    assert all(n.split(":", 1)[0] == s.name for s in pk.SOURCES for n in (*s.photos, *s.videos, *s.distractors))


def _seen(found: bool) -> Detection:
    return Detection(found, 160.0, 120.0, 40.0, 0.9 if found else 0.0, 320, 240, 2.0)


def test_laser_on_frames_count_a_confirmed_gate_off_the_ball_or_without_one() -> None:
    # N (controller.confirm_frames) is 3: frames 3 and 4 of five sightings in a row are confirmed
    empty = vs.Sequence("empty", "video", tuple(_seen(True) for _ in range(5)), ())
    assert sq.laser_frames(empty) == 3
    on_ball = vs.Sequence("target", "video", tuple(_seen(True) for _ in range(5)), ((160.0, 120.0),) * 5, 40.0)
    assert sq.laser_frames(on_ball) == 0
    # centred (the laser's conditions hold for a target run) but 40 px from the ball
    off_ball = vs.Sequence("target", "video", tuple(_seen(True) for _ in range(5)), ((120.0, 120.0),) * 5, 40.0)
    assert sq.laser_frames(off_ball) == 3
    broken = vs.Sequence("empty", "video", (_seen(True), _seen(True), _seen(False), _seen(True), _seen(True)), ())
    assert sq.laser_frames(broken) == 0


def test_target_runs_are_drawn_where_the_pilot_fires() -> None:
    """The gate confirms a ball only within the fire range: target runs beyond it could never confirm."""
    from pilot.common.config import PilotConfig

    config = PilotConfig()
    lo, hi = vs.firing_sizes(config)
    focal = (vi.W / 2) / np.tan(np.radians(config.controller.horizontal_fov_deg) / 2)
    at_fire_range = config.hsv.target_diameter_m * focal / config.controller.fire_range_max_m
    assert at_fire_range < lo < hi == 120.0
    nearer = dataclasses.replace(config, controller=dataclasses.replace(config.controller, fire_range_max_m=1.0))
    assert vs.firing_sizes(nearer)[0] == pytest.approx(2 * lo)
