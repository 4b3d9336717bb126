"""The one range rule (pilot/common/ranges.py) and the two checkers that share it: the config's options and the
simulated world's figures refuse NaN, infinities, booleans and non-numbers alike, and keep their own messages."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from pilot.common.config import from_dict
from pilot.common.errors import ConfigError
from pilot.common.ranges import within
from pilot.sim.randomise import Effects


@pytest.mark.parametrize("value", [0, 1, 0.5, 1.0, np.float64(0.25), np.int64(1), Fraction(1, 3)])
def test_a_finite_number_in_the_range_is_within(value: object) -> None:
    assert within(value, 0, 1)


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf, -0.01, 1.01, 10**400, -(10**400), True, False,
                                   "0.5", None, [0.5], np.float64("nan"), complex(0.5, 0)])
def test_anything_else_is_not(value: object) -> None:
    assert not within(value, 0, 1)  # True and False too, though they compare as 1 and 0


@pytest.mark.parametrize("value", [True, False])
def test_the_simulated_world_refuses_a_boolean_for_a_figure(value: bool) -> None:
    with pytest.raises(ConfigError, match=f"simulator parameter shadows = {value!r}: outside its physical range 0..1"):
        Effects(shadows=value)
    assert Effects(shadows=1.0).shadows == 1.0


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf, 100.0])
def test_the_config_refuses_a_non_finite_figure_with_its_own_message(value: float) -> None:
    with pytest.raises(ConfigError, match=r"^p\.yaml: option 'vision\.max_jump' must be within 0\.01\.\.1, got "):
        from_dict({"vision": {"max_jump": value}}, "p.yaml")
    with pytest.raises(ConfigError, match=r"^p\.yaml: option 'link\.rate_hz' must be within 1\.\.50, got "):
        from_dict({"link": {"rate_hz": value}}, "p.yaml")
