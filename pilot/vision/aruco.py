"""The ArUco marker detector, with parameters for the frames a drone sees: blur, the frame's edge, dim light.

OpenCV's parameters were chosen on bench/vision's tuning photos for recall under motion blur and at the frame's
edge, no false positive, and a cost near OpenCV's defaults (each choice and its figures: bench/vision/HISTORY.md,
"The ArUco detector's parameters"). A frame without a marker gets a second look at half resolution and, while the
frame's budget lasts, a look for a marker with one corner covered (aruco_corner.py). Every marker of the configured
id is a candidate; its size must imply a plausible range.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import cv2
import numpy as np
from cv2.typing import MatLike

from ..common.config import ArucoConfig, VisionConfig
from ..common.errors import ConfigError
from .aruco_corner import corner_covered_markers, reference_cells
from .budget import FrameBudget
from .detection import Candidate, Detection, best_detection, frame_size, malformed, range_of


def aruco_dictionary(name: str) -> cv2.aruco.Dictionary:
    code = getattr(cv2.aruco, name, None)
    if not name.startswith("DICT_") or not isinstance(code, int):
        raise ConfigError(f"aruco.dictionary: unknown ArUco dictionary {name!r} (e.g. DICT_4X4_50)")
    return cv2.aruco.getPredefinedDictionary(code)


MIN_SIDE_PX = 8  # the smallest marker side searched, pixels of the searched image
CORNER_SCORE = 0.8  # a marker read with a corner covered: above the acquisition threshold, below a whole one
CORNER_MIN_SIDE = 20  # px: a covered marker's cells are read from 3 px and more (a 9 px quad of a red shape's
# texture matched the marker's cells with one to spare)


def detector_parameters(adaptive_thresh_constant: float, searched_width: int = 320) -> cv2.aruco.DetectorParameters:
    params = cv2.aruco.DetectorParameters()
    params.adaptiveThreshConstant = adaptive_thresh_constant
    params.adaptiveThreshWinSizeMin = 3
    params.adaptiveThreshWinSizeMax = 23
    params.adaptiveThreshWinSizeStep = 20
    params.minMarkerPerimeterRate = min(1.0, 4.0 * MIN_SIDE_PX / max(1, searched_width))
    params.polygonalApproxAccuracyRate = 0.05
    params.perspectiveRemovePixelPerCell = 8
    params.minDistanceToBorder = 0
    params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_SUBPIX
    params.cornerRefinementWinSize = 3
    return params


class ArucoMarkerDetector:
    name = "aruco"

    def __init__(
        self, config: ArucoConfig | None = None, vision: VisionConfig | None = None, fov_deg: float = 60.0,
        clock: Callable[[], float] | None = None,
    ) -> None:
        """``clock``: seconds, for the frame's budget (default ``pilot.vision.budget.CLOCK``)."""
        cfg = config or ArucoConfig()
        self.cfg = cfg
        self.marker_id = cfg.marker_id
        self.vision = vision or VisionConfig()
        self.fov_deg = fov_deg
        self._dictionary = aruco_dictionary(cfg.dictionary)
        self._detectors: dict[int, cv2.aruco.ArucoDetector] = {}  # per searched width (the minimum perimeter)
        self._references = reference_cells(self._dictionary, max(0, cfg.marker_id))
        self.budget = FrameBudget(self.vision.budget_ms, clock)

    def _detector(self, searched_width: int) -> cv2.aruco.ArucoDetector:
        det = self._detectors.get(searched_width)
        if det is None:
            params = detector_parameters(self.cfg.adaptive_thresh_constant, searched_width)
            det = self._detectors[searched_width] = cv2.aruco.ArucoDetector(self._dictionary, params)
        return det

    def _markers(self, grey: MatLike, scale: float, width: int) -> list[Candidate]:
        corners, ids, _ = self._detector(max(grey.shape[:2])).detectMarkers(grey)
        if ids is None or len(corners) == 0:
            return []
        quads = [q for q, m in zip(corners, np.asarray(ids).reshape(-1))
                 if self.marker_id < 0 or int(m) == self.marker_id]
        return self._placed(quads, scale, width, 1.0)

    def _placed(self, quads: Sequence[MatLike], scale: float, width: int, score: float) -> list[Candidate]:
        """The markers of ``quads`` (corners in a ``scale`` times smaller image) whose size implies a plausible
        range, as candidates scored ``score``, largest first."""
        found = []
        for quad in quads:
            pts = np.asarray(quad, dtype=np.float64).reshape(4, 2) * scale
            side = float(np.linalg.norm(pts - np.roll(pts, 1, axis=0), axis=1).mean())
            distance = range_of(side, self.cfg.marker_size_m, width, self.fov_deg)
            if self.vision.range_min_m <= distance <= self.vision.range_max_m:
                centre = pts.mean(axis=0)
                found.append(Candidate(float(centre[0]), float(centre[1]), side, score))
        return sorted(found, key=lambda c: c.size, reverse=True)

    def candidates(self, image: MatLike) -> list[Candidate]:
        """Every candidate, best first; an empty list for a frame ``detection.malformed`` names (no OpenCV error)."""
        if malformed(image) is not None:
            return []
        self.budget.start()
        grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
        width = frame_size(image)[0]
        found = self._markers(grey, 1.0, width)
        if not found:
            found = self._markers(cv2.pyrDown(grey), 2.0, width)  # pyrDown's pixel j is centred on pixel 2j
        if not found and self.marker_id >= 0:  # one id to match: a covered corner's few cells are enough
            covered = corner_covered_markers(grey, self._references, CORNER_MIN_SIDE, lambda: not self.budget.out())
            found = self._placed(covered, 1.0, width, CORNER_SCORE)
        return found

    def detect(self, image: MatLike) -> Detection:
        """This frame alone, the best candidate (no tracking, no frame checks)."""
        return best_detection(self, image, self.cfg.marker_size_m, self.fov_deg)

    @property
    def cut_short(self) -> bool:
        """Whether the last frame's covered-corner look stopped at the frame's budget."""
        return self.budget.exhausted

    def aim_on_target(self, image: MatLike, size: float) -> bool | None:
        """Not measured: a marker is black and white like much else, and a marker partly covered is not read."""
        return None

    def candidates_near(self, image: MatLike, cx: float, cy: float, size: float) -> list[Candidate]:
        """A tracked marker the frame's look missed: the covered-corner look in a window twice its size where the
        track expects it, whatever the budget (a window costs a fraction of a frame's look)."""
        if malformed(image) is not None or self.marker_id < 0:
            return []
        w, h = frame_size(image)
        x0, y0 = max(0, int(cx - size)), max(0, int(cy - size))
        x1, y1 = min(w, int(cx + size) + 1), min(h, int(cy + size) + 1)
        if min(x1 - x0, y1 - y0) < CORNER_MIN_SIDE:
            return []
        grey = cv2.cvtColor(np.ascontiguousarray(image[y0:y1, x0:x1]), cv2.COLOR_BGR2GRAY)
        offset = np.array((x0, y0), np.float64)
        quads = [q + offset for q in corner_covered_markers(grey, self._references, CORNER_MIN_SIDE)]
        return self._placed(quads, 1.0, w, CORNER_SCORE)
