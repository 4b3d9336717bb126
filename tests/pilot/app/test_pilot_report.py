"""``pilot report DIR``: a recording made by the real Recorder (the runner flying the fake drone on an injected clock)
becomes one page that headless Chromium shows with every chart and the path, and fetches nothing; the failure
reason of a flight that never fired; bad folders and logs get one line, exit 2, nothing written."""

from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pytest
from controller_rig import MISS, seen
from fake_drone import FakeDrone
from runner_rig import Clock, Frames
from selenium import webdriver
from selenium.webdriver.common.by import By

from pilot.app.record import Recorder
from pilot.app.report import main
from pilot.app.runner import run
from pilot.common.config import ControllerConfig
from pilot.control.controller import Controller
from pilot.vision.detect import Detection

REPO = Path(__file__).resolve().parents[3]
browser = importlib.import_module("test_pilot_liveview").browser  # the headless Chromium fixture, shared


class Sees:
    name = "fixed"

    def __init__(self, det: Detection) -> None:
        self.det = det

    def detect(self, image: np.ndarray) -> Detection:
        return self.det


def record(folder: Path, det: Detection, seconds: float) -> Path:
    clock = Clock()
    controller = Controller(ControllerConfig(), clock=clock.now)
    with Recorder(folder) as rec:
        result = run(Frames(clock), Sees(det), controller, FakeDrone(clock.now), clock, max_seconds=seconds,
                     keepalive_ms=200, observers=[rec])
        rec.write({"result": {"reason": result.reason, "transitions": [
            {"t_ms": t.t_ms, "from": t.old.value, "to": t.new.value, "why": t.reason}
            for t in controller.transitions]}})
    cv2.imwrite(str(folder / "path.png"), np.full((60, 80, 3), 200, np.uint8))
    return folder


def report(folder: Path) -> tuple[int, str]:
    lines: list[str] = []
    code = main([str(folder)], out=lines.append)
    return code, "\n".join(lines)


def test_the_page_shows_every_chart_and_the_path_and_fetches_nothing(
    tmp_path: Path, browser: webdriver.Chrome
) -> None:
    folder = record(tmp_path / "rec", seen(size=0.25), 60.0)
    code, out = report(folder)
    assert code == 0 and out == f"pilot report: {folder / 'report.html'}"
    page = (folder / "report.html").read_text()
    assert "http:" not in page and "https:" not in page and "<script" not in page
    browser.get((folder / "report.html").as_uri())
    states = {e.get_attribute("data-state") for e in browser.find_elements(By.CSS_SELECTOR, "#timeline rect")}
    assert {"arm", "takeoff", "fire", "land", "done"} <= states
    assert browser.find_elements(By.CSS_SELECTOR, "#commands circle")
    for chart in ("confidence", "laser"):
        points = browser.find_element(By.CSS_SELECTOR, f"#{chart} polyline").get_attribute("points") or ""
        assert len(points.split()) > 100, chart
    assert browser.find_element(By.CSS_SELECTOR, "#link polyline.replies").is_displayed()
    assert browser.execute_script("return document.getElementById('path').naturalWidth") == 80
    assert "ok" in (browser.find_element(By.ID, "failure").get_attribute("class") or "")
    fetched = browser.execute_script("return performance.getEntriesByType('resource').map(e => e.name)")
    assert all(str(name).startswith("data:") for name in fetched), fetched
    box = browser.execute_script("return document.getElementById('timeline').getBoundingClientRect().width")
    assert box > 900


def test_a_flight_that_never_fired_names_why(tmp_path: Path) -> None:
    folder = record(tmp_path / "rec", MISS, 40.0)
    assert report(folder)[0] == 0
    page = (folder / "report.html").read_text()
    failure = page.split('<p id="failure" class="fail">Failure: ', 1)[1].split("</p>", 1)[0]
    assert "from search" in failure and "the laser never came on" in failure, failure


@pytest.mark.parametrize("content, message", [
    (None, "no log.jsonl here: name a folder written by --record"),
    ('{"t": 0.1, "tick": 0, "state": "arm", "replies": []}\nnot json\n', "log.jsonl:2: not a JSON object"),
    ('{"t": 0.1, "tick": 0, "state": 3}\n', "log.jsonl:1: neither a tick, a link entry nor the result"),
    ('{"link": "rx", "t": 0.1, "data": "A"}\n', "log.jsonl: no tick recorded: nothing to report"),
])
def test_a_bad_folder_or_log_gets_one_line_and_nothing_is_written(tmp_path: Path, content: str | None,
                                                                  message: str) -> None:
    if content is not None:
        (tmp_path / "log.jsonl").write_text(content)
    proc = subprocess.run([sys.executable, "-m", "pilot", "report", str(tmp_path)], cwd=REPO, capture_output=True,
                          text=True, timeout=60)
    assert proc.returncode == 2 and proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("pilot report: error: ") and message in lines[0], lines
    assert not (tmp_path / "report.html").exists()
