"""``--serve``: the live view in a real headless Chromium (Debian's chromium + chromium-driver, via Selenium)
against a simulated flight, and its HTTP surface (token, 404s, the address option)."""

from __future__ import annotations

import json
import os
import queue
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from pathlib import Path

import pytest
from browser_rig import browser_session
from selenium import webdriver
from selenium.webdriver.common.by import By

from pilot.app.liveview import LiveView, parse_address
from pilot.app.observers import StopSwitch
from pilot.common.errors import PilotError

REPO = Path(__file__).resolve().parents[3]


@pytest.fixture
def browser(tmp_path: Path) -> Iterator[webdriver.Chrome]:
    yield from browser_session(tmp_path)


class Pilot:
    """``python -m pilot ... --serve 127.0.0.1:0`` in a subprocess; its output lines in a queue."""

    def __init__(self, *args: str) -> None:
        env = {**os.environ, "PYTHONUNBUFFERED": "1"}
        self.proc = subprocess.Popen([sys.executable, "-m", "pilot", *args], cwd=REPO, env=env, text=True,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        self.lines: queue.Queue[str] = queue.Queue()
        self.out: list[str] = []
        assert self.proc.stdout is not None
        self._pumping = threading.Thread(target=self._pump, args=(self.proc.stdout,), daemon=True)
        self._pumping.start()

    def _pump(self, stream: object) -> None:
        for line in stream:  # type: ignore[attr-defined]
            self.out.append(line)
            self.lines.put(line)

    def url(self, timeout: float = 90) -> str:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                line = self.lines.get(timeout=1)
            except queue.Empty:
                assert self.proc.poll() is None, self.finish()
                continue
            if line.startswith("live view: "):
                return line.split()[2]
        raise AssertionError("no live view URL printed")

    def finish(self, timeout: float = 90) -> str:
        self.proc.wait(timeout=timeout)
        self._pumping.join(timeout=10)
        assert self.proc.stderr is not None
        return "".join(self.out) + self.proc.stderr.read()


def _get(url: str, data: bytes | None = None) -> tuple[int, bytes]:
    try:
        with urllib.request.urlopen(urllib.request.Request(url, data=data), timeout=5) as resp:
            return resp.status, resp.read()
    except urllib.error.HTTPError as exc:
        return exc.code, b""


def _state(url: str) -> dict[str, object]:
    status, body = _get(url + "state.json")
    assert status == 200
    state: dict[str, object] = json.loads(body)
    return state


def test_stop_in_the_browser_lands_the_simulated_drone_and_turns_the_laser_off(
    virtual_drone: Path, tmp_path: Path, browser: webdriver.Chrome
) -> None:
    config = tmp_path / "pilot.yaml"
    config.write_text("controller:\n  fire_ms: 20000\n")  # the laser stays on until Stop
    rec = tmp_path / "rec"
    pilot = Pilot("--virtual-drone", str(virtual_drone), "--scenario", "ahead", "--seed", "2", "--ideal", "--config",
                  str(config), "--serve", "127.0.0.1:0", "--record", str(rec), "--no-status")
    try:
        url = pilot.url()
        base = url.rsplit("/", 2)[0]
        assert url.startswith("http://127.0.0.1:") and len(url.rstrip("/").rsplit("/", 1)[1]) >= 16
        # without the token: nothing, and no stop
        assert _get(base + "/")[0] == 404 and _get(base + "/stop", b"")[0] == 404
        assert _get(base + "/x" + url.rsplit("/", 2)[1] + "/stop", b"")[0] == 404

        browser.get(url)
        frame = browser.find_element(By.ID, "frame")
        deadline = time.monotonic() + 30
        while browser.execute_script("return window.liveView.frames") < 3:
            assert time.monotonic() < deadline, "no frames shown"
            time.sleep(0.1)
        first, n1 = frame.screenshot_as_png, browser.execute_script("return window.liveView.frames")
        time.sleep(1.0)
        second, n2 = frame.screenshot_as_png, browser.execute_script("return window.liveView.frames")
        assert n2 > n1 + 5 and first != second, "the frames do not change"

        deadline = time.monotonic() + 60
        while browser.find_element(By.ID, "laser").text != "ON":
            assert time.monotonic() < deadline and pilot.proc.poll() is None, "the laser never came on"
            time.sleep(0.05)
        assert browser.find_element(By.ID, "state").text == "fire"
        assert browser.find_element(By.ID, "confidence").text not in ("", "-")
        assert browser.find_element(By.ID, "log").text.strip(), "no commands shown"
        browser.find_element(By.ID, "stop").click()
        output = pilot.finish()
    finally:
        if pilot.proc.poll() is None:
            pilot.proc.kill()
            pilot.proc.wait()
    assert "stopped on request: Stop from the live view (127.0.0.1)" in output, output
    assert "drone:     laser off, disarmed, altitude 0.00 m" in output, output  # the virtual drone's outputs
    ticks = [json.loads(line) for line in (rec / "log.jsonl").read_text().splitlines()]
    ticks = [t for t in ticks if "tick" in t]
    assert ticks[-1]["laser"] is True and ticks[-1]["state"] == "fire"  # lit when Stop came
    assert pilot.proc.returncode == 130


def test_the_view_serves_its_token_only_and_stop_requests_the_switch() -> None:
    stop = StopSwitch()
    with LiveView("127.0.0.1", 0, stop) as view:
        url = view.url
        assert _get(url)[0] == 200 and b"STOP" in _get(url)[1]
        assert _state(url)["state"] == "starting"
        assert _get(url.replace(view.token, "wrong") + "stop", b"")[0] == 404 and not stop.requested
        assert _get(url + "stop")[0] == 404  # GET does not stop
        assert _get(url + "stop", b"")[0] == 200 and stop.requested
        assert _state(url)["stop_requested"] is True


@pytest.mark.parametrize(("text", "expected"), [("8080", ("127.0.0.1", 8080)), (":0", ("127.0.0.1", 0)),
                                                ("0.0.0.0:9000", ("0.0.0.0", 9000)), ("[::1]:80", ("::1", 80))])
def test_serve_address(text: str, expected: tuple[str, int]) -> None:
    assert parse_address(text) == expected


@pytest.mark.parametrize("text", ["", "host", "host:port", "99999", "-1"])
def test_bad_serve_address_names_the_option(text: str) -> None:
    with pytest.raises(PilotError, match="option --serve"):
        parse_address(text)
