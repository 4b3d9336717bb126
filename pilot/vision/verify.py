"""A learned verifier of ball candidates: a veto on what the colour rules alone would act on.

The colour-ball detector's false detections are small red patches a person would never call a ball (a letter of a
sign, a knot of clothing, cut fruit); a rule per photo does not end them. A small network (one hidden layer), trained
in bench/vision/train_verifier.py on the detector's own candidates on composites of the tuning sources (positives:
candidates on the ball; negatives: candidates on empty and distractor views), scores each candidate's window
(verify_features.py). ``VerifiedSource`` wraps a detector: of its candidates, the first ``MAX_VERIFIED`` are kept
when the verifier passes them, the rest dropped, so neither the tracker nor the laser's gate acts on a vetoed one and
the cost stays bounded. The model ships as ``verifier.yaml`` (OpenCV's FileStorage text format; OpenCV 5 has no
``cv2.ml``), its version and its features' version checked at load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt
from cv2.typing import MatLike

from ..common.errors import ConfigError
from . import verify_features as vf
from .detection import Candidate, CandidateSource

FORMAT = "drone pilot ball verifier"
VERSION = 1
MODEL = Path(__file__).with_name("verifier.yaml")
MAX_VERIFIED = 4  # candidates looked at per frame (best first): the rest are dropped
FloatArray = npt.NDArray[np.float32]
LAYERS = ("mean", "scale", "w0", "b0", "w1", "b1")


@dataclass(frozen=True)
class Verifier:
    mean: FloatArray  # the features' standardisation
    scale: FloatArray
    w0: FloatArray  # LENGTH x hidden
    b0: FloatArray
    w1: FloatArray  # hidden x 1
    b1: FloatArray
    threshold: float  # a candidate scoring below it is vetoed

    def score(self, image: MatLike, c: Candidate) -> float:
        """0..1: how much the candidate's window looks like the ball's."""
        x = (vf.features(image, c) - self.mean) / self.scale
        hidden = np.maximum(x @ self.w0 + self.b0, 0.0)
        logit = float((hidden @ self.w1 + self.b1)[0])
        return 1.0 / (1.0 + math.exp(-max(-60.0, min(60.0, logit))))

    def passes(self, image: MatLike, c: Candidate) -> bool:
        return self.score(image, c) >= self.threshold


def save(v: Verifier, path: str | Path) -> None:
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    fs.write("format", FORMAT)
    fs.write("version", VERSION)
    fs.write("features_version", vf.VERSION)
    fs.write("threshold", v.threshold)
    for name in LAYERS:
        a = np.asarray(getattr(v, name), np.float32)
        fs.write(name, a.reshape(-1, 1) if a.ndim == 1 else a)
    fs.release()


def load(path: str | Path = MODEL) -> Verifier:
    """The verifier in ``path``; a ConfigError naming the file if it is missing, truncated, corrupt or of another
    version."""
    where = f"ball verifier {str(path)!r}"
    if not Path(path).is_file():
        raise ConfigError(f"{where}: no such file (reinstall the pilot)")
    try:
        fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
    except (cv2.error, SystemError):  # OpenCV 5's constructor reports its parse error as a SystemError
        raise ConfigError(f"{where}: corrupt or truncated (not OpenCV's YAML): reinstall the pilot") from None
    try:
        if fs.getNode("format").string() != FORMAT:
            raise ConfigError(f"{where}: not a ball verifier (format {fs.getNode('format').string()!r})")
        version, features = int(fs.getNode("version").real()), int(fs.getNode("features_version").real())
        if (version, features) != (VERSION, vf.VERSION):
            raise ConfigError(f"{where}: version {version} with features {features}, this pilot reads version "
                              f"{VERSION} with features {vf.VERSION}: retrain it (make bench-verifier)")
        threshold = fs.getNode("threshold").real()
        arrays = [fs.getNode(name).mat() for name in LAYERS]
    finally:
        fs.release()
    missing = [n for n, a in zip(LAYERS, arrays) if a is None]
    if missing:
        raise ConfigError(f"{where}: corrupt or truncated (missing {', '.join(missing)}): reinstall the pilot")
    mean, scale, w0, b0, w1, b1 = (np.asarray(a, np.float32) for a in arrays)
    hidden = w0.shape[1] if w0.ndim == 2 else 0
    shapes_ok = (mean.size == scale.size == vf.LENGTH and w0.shape == (vf.LENGTH, hidden) and b0.size == hidden
                 and w1.shape == (hidden, 1) and b1.size == 1 and hidden > 0)
    finite = all(np.isfinite(a).all() for a in (mean, scale, w0, b0, w1, b1)) and bool((scale > 0).all())
    if not shapes_ok or not finite or not 0.0 < threshold < 1.0:
        raise ConfigError(f"{where}: corrupt (layers {w0.shape}, threshold {threshold}): reinstall the pilot")
    return Verifier(mean.ravel(), scale.ravel(), w0, b0.ravel(), w1, b1.ravel(), threshold)


@cache
def shipped() -> Verifier:
    """The verifier shipped with the pilot (``MODEL``), read once."""
    return load(MODEL)


class VerifiedSource:
    """A candidate source whose candidates the verifier has passed (at most ``MAX_VERIFIED`` per frame)."""

    def __init__(self, source: CandidateSource, verifier: Verifier) -> None:
        self.source = source
        self.verifier = verifier
        self.name = source.name

    @property
    def cut_short(self) -> bool:
        return self.source.cut_short

    def _passed(self, image: MatLike, candidates: list[Candidate]) -> list[Candidate]:
        return [c for c in candidates[:MAX_VERIFIED] if self.verifier.passes(image, c)]

    def candidates(self, image: MatLike) -> list[Candidate]:
        return self._passed(image, self.source.candidates(image))

    def aim_on_target(self, image: MatLike, size: float) -> bool | None:
        return self.source.aim_on_target(image, size)

    def candidates_near(self, image: MatLike, cx: float, cy: float, size: float) -> list[Candidate]:
        return self._passed(image, self.source.candidates_near(image, cx, cy, size))
