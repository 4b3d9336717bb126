"""The overlay's outlined text: the dark rim hugs the light letters, so no letter shows twice ("landd")."""

from __future__ import annotations

import numpy as np
import pytest

from pilot.app.overlay import outlined_text


@pytest.mark.parametrize("scale", [0.45, 0.9, 1.4])
@pytest.mark.parametrize("text", ["land", "12.34s land", "cmd il0000"])
def test_the_rim_ends_where_the_letters_end(text: str, scale: float) -> None:
    img = np.full((120, 900, 3), 128, np.uint8)
    outlined_text(img, text, (10, 80), scale)
    light = np.nonzero(img[:, :, 0] > 200)[1]
    dark = np.nonzero(img[:, :, 0] < 60)[1]
    assert light.size and dark.size
    assert dark.max() <= light.max() + 2  # a rim of about a pixel, not a shifted copy of the last letters
    assert dark.min() >= light.min() - 2
