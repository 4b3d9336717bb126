"""The Raspberry Pi vision pilot: find the target with OpenCV and fly to it over the drone protocol."""

from __future__ import annotations

__all__ = ["__version__"]

__version__ = "0.1.0"
