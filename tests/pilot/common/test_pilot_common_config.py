"""Options checked at start-up whichever detector flies: a wrong ``aruco.dictionary`` is refused like every other
bad option (one line naming the option and the file, exit 2), not left to fail when the detector is switched; a
fire range shorter than where the approach stops is refused, naming the figure to use."""

from __future__ import annotations

from pathlib import Path

import pytest
from cli_rig import call

from pilot.common.config import from_dict
from pilot.common.errors import ConfigError


@pytest.mark.parametrize("detector", ["hsv", "aruco"])
@pytest.mark.parametrize("name", ["DICT_4X4_51", "dict_4x4_50", "DICT_", "getPredefinedDictionary", ""])
def test_an_unknown_aruco_dictionary_is_refused_naming_the_option(detector: str, name: str) -> None:
    with pytest.raises(ConfigError, match=r"^pilot\.yaml: option 'aruco\.dictionary' must be one of .*got '"):
        from_dict({"detector": detector, "aruco": {"dictionary": name}}, "pilot.yaml")


@pytest.mark.parametrize("name", ["DICT_4X4_50", "DICT_6X6_250", "DICT_ARUCO_ORIGINAL", "DICT_APRILTAG_36h11"])
def test_opencv_predefined_dictionaries_are_accepted(name: str) -> None:
    assert from_dict({"detector": "hsv", "aruco": {"dictionary": name}}).aruco.dictionary == name


def test_the_command_line_refuses_it_at_start_up_with_the_hsv_detector(tmp_path: Path) -> None:
    config = tmp_path / "pilot.yaml"
    config.write_text("detector: hsv\naruco:\n  dictionary: DICT_4X4_51\n", encoding="utf-8")
    code, out, err = call("--config", str(config), "--dry-run", "--no-status", "--max-seconds", "0.2")
    assert code == 2 and out == "", (code, out, err)
    assert err.count("\n") == 1 and "aruco.dictionary" in err and str(config) in err and "Traceback" not in err, err


@pytest.mark.parametrize("detector", ["hsv", "aruco"])
def test_a_fire_range_the_approach_never_reaches_is_refused_with_the_figure(detector: str) -> None:
    # the 0.3 m target at 0.19 of a 60° frame is about 1.37 m away: AIM fires within 0.8 of the range, so 1.71 m
    with pytest.raises(ConfigError, match=r"^pilot\.yaml: option 'controller\.fire_range_max_m' \(1\.5\) is too "
                                          r"short: the approach stops about 1\.37 m .* set it above 1\.71 m"):
        from_dict({"detector": detector, "controller": {"fire_range_max_m": 1.5}}, "pilot.yaml")
    accepted = from_dict({"detector": detector, "controller": {"fire_range_max_m": 1.75}})
    assert accepted.controller.fire_range_max_m == 1.75


def test_a_short_fire_range_is_accepted_where_the_approach_stops_nearer() -> None:
    options = {"controller": {"fire_range_max_m": 1.5, "approach_size": 0.25}, "hsv": {"target_diameter_m": 0.3}}
    assert from_dict(options).controller.fire_range_max_m == 1.5
    with pytest.raises(ConfigError, match="fire_range_max_m"):  # a bigger ball stops the approach further away
        from_dict({**options, "hsv": {"target_diameter_m": 0.4}})
