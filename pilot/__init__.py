"""The Raspberry Pi vision pilot: find the target with OpenCV and fly to it over the drone protocol.

Layers, each importing only those below it (ARCHITECTURE.md): ``app`` (command line, runner, recording, live
view) over ``control`` (the state machine) and ``sim`` (the simulated room and drone), over ``vision`` (frames,
detectors, tracking, gating) and ``link`` (the serial link and the drone's view), over ``common`` (config,
errors); all of them reach the protocol only through the generated ``drone_protocol`` module."""

from __future__ import annotations

from .common.version import __version__

__all__ = ["__version__"]
