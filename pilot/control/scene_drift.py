"""The drift read from the whole scene's motion (``pilot.vision.motion``), for the frames the target cannot give it.

``trim.Drift`` learns from the target: in a search that turns, or from a far ball that flickers, it learns nothing,
and a trim error of 0.3-0.5 m/s carries the drone into a wall in the 10-20 s such a search lasts. The scene moves in
every frame: what the camera seems to have turned beyond the turn the yaw commands made is the drone sliding
sideways, the scene's growth is it moving forward. Either is an angle or a ratio, a speed divided by the depth of
the scene; the depth is not known, so a room's typical ``DEPTH_M`` stands for it. The trim integrates the speeds
until the scene stands still, so a wrong depth changes how fast the trim is learnt, not what it settles on.
"""

from __future__ import annotations

import math

from ..vision.detection import SceneShift

DEPTH_M = 2.5  # a room's walls and furniture, as far as the camera sees them (3-8 m rooms, the drone inside)
MAX_MPS = 1.0  # a frame's reading beyond this is a fit gone wrong (the trim error is at most about 0.5 m/s)
MIN_DT_S = 0.01
# the share of the target's learning rate the scene's speeds get: a search's turns take most frames, the trim is leant
# only in the frames they leave (``TrimSticks``), and the speed answers a lean over seconds, so the full rate wound
# the trim up to four times what the drift needed while the speed had barely turned (`high` 3015: -1.4° for -0.37°)
GAIN = 0.3


def scene_speeds(scene: SceneShift | None, turned_deg: float, dt: float) -> tuple[float, float] | None:
    """The drone's speed (m/s) to the right and forward from ``scene``, the scene's motion over ``dt`` seconds in
    which the yaw commands turned the body ``turned_deg`` (clockwise positive), times ``GAIN`` (what the trim
    learns from); None without a reading."""
    if scene is None or dt < MIN_DT_S:
        return None
    right = math.radians(scene.turn_deg - turned_deg) * DEPTH_M / dt  # sliding right: the scene slides left
    forward = (scene.scale - 1.0) * DEPTH_M / dt
    return GAIN * _clamp(right), GAIN * _clamp(forward)


def _clamp(value: float) -> float:
    return max(-MAX_MPS, min(MAX_MPS, value))
