"""bench/vision/vision_dev.py, the dev seed sets' records and their comparison (how bench/vision/HISTORY.md measures a
detector change): the counts it reports, and a small record's round trip."""

from __future__ import annotations

from pathlib import Path

import pytest
import vision_dev as dev


def _ball(score: float, at: tuple[float, float] = (50.0, 40.0), group: str = "jpeg", size: float = 20.0) -> dev.View:
    """A 20 px ball at (50, 40), and its one candidate (none if ``score`` is 0)."""
    return dev.View("target", group, size, 50.0, 40.0, "coffee", [(*at, size, score)] if score else [])


def _empty(score: float, group: str = "warm") -> dev.View:
    return dev.View("empty", group, 0.0, 0.0, 0.0, "", [(10.0, 10.0, 18.0, score)] if score else [])


def test_a_ball_counts_where_the_best_candidate_scores_at_the_truth() -> None:
    assert dev.correct(_ball(0.6), 0.6)
    assert not dev.correct(_ball(0.59), 0.6)
    assert dev.correct(_ball(0.9, at=(54.0, 43.0)), 0.6)  # within 30 % of its size (5 of 6 px)
    assert not dev.correct(_ball(0.9, at=(57.0, 40.0)), 0.6)
    assert not dev.correct(_ball(0.0), 0.6)
    assert dev.correct(_ball(1.0, at=(52.9, 40.0), size=8.0), 0.6)  # at least 3 px


def test_compare_counts_balls_gained_and_lost_and_false_detections_by_group() -> None:
    before = [_ball(0.5, group="jpeg"), _ball(0.8, group="dim"), _ball(0.7, group="clean"),
              _ball(0.0, size=12.0), _empty(0.0), _empty(0.7, "pink"), _empty(0.3)]
    after = [_ball(0.65, group="jpeg"), _ball(0.4, group="dim"), _ball(0.7, group="clean"),
             _ball(0.9, size=12.0),  # under 16 px: not counted
             _empty(0.61), _empty(0.2, "pink"), _empty(0.3)]
    d = dev.compare(before, after, 0.6)
    assert d.balls == (2, 2, 3)
    assert (d.gained, d.lost) == (["jpeg"], ["dim"])
    assert d.false == (1, 1)
    assert (d.new_false, d.gone_false) == (["warm"], ["pink"])
    assert d.differ == 5


def test_compare_refuses_records_of_different_sets() -> None:
    with pytest.raises(SystemExit, match="not the same set"):
        dev.compare([_ball(0.7)], [_ball(0.7), _empty(0.0)], 0.6)


def test_a_small_record_round_trips_and_compares_equal(tmp_path: Path) -> None:
    views = dev.views_of("tun", per_condition=1)  # a view per condition, two empty ones
    assert [v.kind for v in views].count("target") == 10 and len(views) == 12
    first = dev.record(views)
    dev.save(first, "a", "tun", tmp_path)
    dev.save(dev.record(views), "b", "tun", tmp_path)
    a, b = dev.load("a", "tun", tmp_path), dev.load("b", "tun", tmp_path)
    assert a == first
    d = dev.compare(a, b, 0.6)
    assert d.differ == 0 and not d.gained and not d.lost and d.false[0] == d.false[1]
    with pytest.raises(SystemExit, match="no such record"):
        dev.load("c", "tun", tmp_path)


def test_the_report_sums_the_sets_both_records_hold(tmp_path: Path) -> None:
    dev.save([_ball(0.5), _ball(0.9, group="dim")], "a", "tun", tmp_path)
    dev.save([_ball(0.7), _ball(0.3, group="dim")], "b", "tun", tmp_path)
    for run, score in (("a", 0.0), ("b", 0.8)):
        dev.save([_empty(score, "pink"), _empty(0.0)], run, "dt", tmp_path)
    dev.save([_empty(0.0)], "a", "dv", tmp_path)  # in one record only
    lines = dev.report("a", "b", 0.6, tmp_path)
    assert lines[0].startswith("tun   balls 1 -> 1 of 2 (+1 -1)")
    assert lines[1] == "      balls gained: jpeg 1; lost: dim 1"
    assert lines[2].startswith("dt    false detections 0 -> 1; records differing 1")
    assert lines[3] == "      false detections new: pink 1; gone: none"
    assert lines[-2] == ("total: balls +1 -1; false detections 0 -> 0 on the target sets, 0 -> 1 of the 2 further "
                         "negatives")
    assert lines[-1].startswith("not in both records: val, tun2, tunx, valx, dv,")
    with pytest.raises(SystemExit, match="no dev set in common"):
        dev.report("a", "c", 0.6, tmp_path)
