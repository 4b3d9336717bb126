"""MuJoCo, imported on first use with a clear message when the simulator's extra is not installed.

The pilot flying a real drone never imports the simulator; the simulator imports MuJoCo only through here, and
selects a headless OpenGL (EGL, else Mesa's OSMesa) unless MUJOCO_GL is already set."""

from __future__ import annotations

import os
from types import ModuleType
from typing import Any

from ..common.errors import SimulatorError

Model = Any  # mujoco.MjModel (MuJoCo ships no type stubs)
Data = Any  # mujoco.MjData

_module: ModuleType | None = None


def module() -> ModuleType:
    global _module
    if _module is None:
        os.environ.setdefault("MUJOCO_GL", "egl")
        try:
            import mujoco
        except ImportError as exc:
            raise SimulatorError(
                "the simulator needs MuJoCo: pip install 'drone-protocol-tools[sim]' (and Debian's libosmesa6 "
                "or libegl1 for headless rendering)"
            ) from exc
        _module = mujoco
    return _module
