"""The learned ball verifier (pilot/vision/verify.py): the shipped model loads and passes the bench's ball, vetoed
candidates never reach the tracker, at most ``MAX_VERIFIED`` are looked at, and a missing, truncated, corrupt or
other-version model file is refused with one error naming it (by the pilot at start: one line, exit 2)."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import cv2
import numpy as np
import pytest
import vision_imagery as vi
from cli_rig import call
from cv2.typing import MatLike

import pilot.vision.verify as verify
import pilot.vision.verify_features as vf
from pilot.common.config import HsvConfig, PilotConfig
from pilot.common.errors import ConfigError
from pilot.vision.detect import make_detector
from pilot.vision.detection import Candidate
from pilot.vision.hsv.detector import HsvBlobDetector


def ball_view(seed: int, size: float) -> tuple[np.ndarray, float, float]:
    """A clean view of a tuning photo with the bench's shaded ball at a known place."""
    rng = np.random.default_rng(seed)
    img = vi.view(rng, ("scikit-image:coffee", "scikit-image:chelsea", "scikit-image:brick"))
    cx, cy = float(rng.uniform(60, 260)), float(rng.uniform(60, 180))
    vi.shaded_ball(img, cx, cy, size, rng)
    return img, cx, cy


def test_shipped_model_loads_and_passes_the_ball() -> None:
    v = verify.load()
    assert 0.0 < v.threshold < 1.0 and v.w0.shape[0] == vf.LENGTH
    passed = 0
    for seed in range(12):
        img, cx, cy = ball_view(seed, 24.0 + 6 * seed)
        c = Candidate(cx, cy, 24.0 + 6 * seed, 0.9)
        assert vf.features(img, c).shape == (vf.LENGTH,)
        passed += v.passes(img, c)
    assert passed >= 11


def test_features_of_a_candidate_at_the_frame_edge() -> None:
    img = np.full((240, 320, 3), 90, np.uint8)
    x = vf.features(img, Candidate(0.0, 239.0, 80.0, 0.5))
    assert x.shape == (vf.LENGTH,) and np.isfinite(x).all()


class Listed:
    """A candidate source that reports fixed candidates."""

    name = "listed"
    cut_short = False

    def __init__(self, found: list[Candidate]) -> None:
        self.found = found

    def candidates(self, image: MatLike) -> list[Candidate]:
        return list(self.found)

    def aim_on_target(self, image: MatLike, size: float) -> bool | None:
        return None

    def candidates_near(self, image: MatLike, cx: float, cy: float, size: float) -> list[Candidate]:
        return list(self.found)


def reddish(v: verify.Verifier) -> verify.Verifier:
    """``v`` rewired to pass a window whose centre is red and veto any other (the first feature: the centre's
    redness)."""
    w0 = np.zeros_like(v.w0)
    w0[0, 0] = 1.0
    w1 = np.zeros_like(v.w1)
    w1[0, 0] = 50.0
    return dataclasses.replace(v, mean=np.zeros_like(v.mean), scale=np.ones_like(v.scale), w0=w0,
                               b0=np.zeros_like(v.b0), w1=w1, b1=np.array([-25.0], np.float32), threshold=0.5)


def test_vetoed_candidates_never_reach_the_caller_and_at_most_max_are_looked_at() -> None:
    img = np.full((240, 320, 3), 128, np.uint8)
    img[100:140, 40:80] = (0, 0, 220)  # red at (60, 120)
    img[100:140, 240:280] = (0, 0, 220)  # red at (260, 120)
    grey, red, late = Candidate(160, 120, 30, 0.9), Candidate(60, 120, 30, 0.8), Candidate(260, 120, 30, 0.1)
    fillers = [Candidate(160, 40 + k, 30, 0.5) for k in range(verify.MAX_VERIFIED)]
    source = verify.VerifiedSource(Listed([grey, red, *fillers, late]), reddish(verify.load()))
    assert source.candidates(img) == [red]  # the grey one vetoed, the red one past MAX_VERIFIED never looked at
    assert source.candidates_near(img, 60, 120, 30) == [red]


def test_make_detector_verifies_the_colour_ball_detector() -> None:
    det = make_detector(PilotConfig())
    assert isinstance(det.source, verify.VerifiedSource) and isinstance(det.source.source, HsvBlobDetector)
    assert isinstance(make_detector(PilotConfig(), verified=False).source, HsvBlobDetector)
    assert not isinstance(make_detector(PilotConfig(hsv=HsvConfig(simple=True))).source, verify.VerifiedSource)


def test_saved_model_reads_back(tmp_path: Path) -> None:
    v = verify.load()
    verify.save(v, tmp_path / "v.yaml")
    back = verify.load(tmp_path / "v.yaml")
    img, cx, cy = ball_view(3, 40.0)
    c = Candidate(cx, cy, 40.0, 0.8)
    assert math.isclose(back.score(img, c), v.score(img, c), rel_tol=1e-5) and back.threshold == v.threshold


@pytest.mark.parametrize("damage", ["missing", "truncated", "corrupt", "version", "features", "other", "nan"])
def test_bad_model_file_is_refused_naming_it(tmp_path: Path, damage: str) -> None:
    path = tmp_path / "verifier.yaml"
    text = verify.MODEL.read_text(encoding="utf-8")
    if damage == "truncated":
        path.write_text(text[: len(text) // 2], encoding="utf-8")
    elif damage == "corrupt":
        path.write_bytes(b"\x00\xff{[: not yaml\n" * 20)
    elif damage == "version":
        path.write_text(text.replace(f"\nversion: {verify.VERSION}\n", "\nversion: 99\n"), encoding="utf-8")
    elif damage == "features":
        path.write_text(text.replace(f"features_version: {vf.VERSION}\n", "features_version: 99\n"),
                        encoding="utf-8")
    elif damage == "other":
        path.write_text(text.replace(verify.FORMAT, "a colour model"), encoding="utf-8")
    elif damage == "nan":
        path.write_text(text.replace("threshold: ", "threshold: .Nan\nx: "), encoding="utf-8")
    with pytest.raises(ConfigError) as err:
        verify.load(path)
    message = str(err.value)
    assert str(path) in message and "\n" not in message
    if damage in ("version", "features"):
        assert "99" in message and "make bench-verifier" in message


def test_the_pilot_refuses_to_start_on_a_corrupt_verifier_in_one_line(tmp_path: Path,
                                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    bad = tmp_path / "verifier.yaml"
    bad.write_text(verify.MODEL.read_text(encoding="utf-8")[:5000], encoding="utf-8")
    monkeypatch.setattr(verify, "MODEL", bad)
    verify.shipped.cache_clear()
    folder = tmp_path / "frames"
    folder.mkdir()
    for k in range(2):
        img, _, _ = ball_view(k, 40.0)
        cv2.imwrite(str(folder / f"f{k}.png"), img)
    try:
        code, out, err = call("--images", str(folder), "--dry-run", "--no-status")
    finally:
        verify.shipped.cache_clear()  # the next test reads the shipped model again
    assert code == 2 and str(bad) in err and len(err.strip().splitlines()) == 1 and "dry-run" not in out
