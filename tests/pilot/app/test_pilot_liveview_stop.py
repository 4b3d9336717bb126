"""The live view's Stop button tells the truth, in a real headless Chromium: "stopping" only once the pilot
answered that it took the stop; retries; a plain failure line on a network error or an HTTP 502 (a proxy
between the browser and the pilot), and the button can be pressed again without reloading.

The page is the pilot's own (liveview.html, with the state a real LiveView reports); the server in front of
it answers Stop as scripted: ``502``, ``drop`` (the connection closes with no answer: a network error), ``ok``.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable, Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib import resources
from pathlib import Path
from typing import Any

import pytest
from browser_rig import browser_session
from selenium import webdriver
from selenium.webdriver.common.by import By

from pilot.app.liveview import LiveView
from pilot.app.observers import StopSwitch

TOKEN = "t0ken"


class Proxy:
    """The page and its state, and a Stop answered as ``script`` says (then ``ok`` once it runs out)."""

    def __init__(self, script: list[str]) -> None:
        self.script = script
        self.posts: list[str] = []
        self.stop_requested = False
        with LiveView("127.0.0.1", 0, StopSwitch()) as view:
            self.state: dict[str, Any] = view.state()
        page = resources.files("pilot.app").joinpath("liveview.html").read_bytes()
        proxy = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, format: str, *args: Any) -> None:
                pass

            def _send(self, status: int, body: bytes, kind: str = "application/json") -> None:
                self.send_response(status)
                self.send_header("Content-Type", kind)
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                self.wfile.write(body)

            def do_GET(self) -> None:
                if self.path == f"/{TOKEN}/":
                    self._send(200, page, "text/html; charset=utf-8")
                elif self.path == f"/{TOKEN}/state.json":
                    self._send(200, json.dumps({**proxy.state, "stop_requested": proxy.stop_requested}).encode())
                else:
                    self._send(404, b"")

            def do_POST(self) -> None:
                what = proxy.script.pop(0) if proxy.script else "ok"
                proxy.posts.append(what)
                if what == "502":
                    self._send(502, b"<html>Bad Gateway</html>", "text/html")
                elif what == "drop":
                    self.close_connection = True
                    self.connection.shutdown(2)
                else:
                    proxy.stop_requested = True
                    self._send(200, json.dumps({"stop_requested": True}).encode())

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.server.daemon_threads = True
        threading.Thread(target=self.server.serve_forever, daemon=True).start()
        self.url = f"http://127.0.0.1:{self.server.server_address[1]}/{TOKEN}/"

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()


@pytest.fixture
def browser(tmp_path: Path) -> Iterator[webdriver.Chrome]:
    yield from browser_session(tmp_path)


def _wait(check: Callable[[], bool], what: str, timeout: float = 20) -> None:
    deadline = time.monotonic() + timeout
    while not check():
        assert time.monotonic() < deadline, what
        time.sleep(0.05)


def _texts(browser: webdriver.Chrome) -> tuple[str, str, bool]:
    button = browser.find_element(By.ID, "stop")
    return button.text, browser.find_element(By.ID, "stop-status").text, button.is_enabled()


@pytest.mark.parametrize(("failure", "said"), [("502", "HTTP 502"), ("drop", "network error")])
def test_a_stop_that_never_reaches_the_pilot_is_said_plainly_and_can_be_pressed_again(
    browser: webdriver.Chrome, failure: str, said: str
) -> None:
    proxy = Proxy([failure] * 3)
    try:
        browser.get(proxy.url)
        browser.find_element(By.ID, "stop").click()
        _wait(lambda: "did NOT reach the pilot" in _texts(browser)[1], "no failure shown")
        button, status, enabled = _texts(browser)
        assert proxy.posts == [failure] * 3 and not proxy.stop_requested  # three tries, none arrived
        assert said in status and "press stop again" in status.lower(), status
        assert "stopping" not in button.lower() and enabled, button
        assert browser.execute_script("return window.liveView.stopSent") is False

        browser.find_element(By.ID, "stop").click()  # again, without reloading: this one arrives
        _wait(lambda: "stopping" in _texts(browser)[0], "the confirmed stop is not shown")
        button, status, enabled = _texts(browser)
        assert proxy.posts == [failure] * 3 + ["ok"] and proxy.stop_requested
        assert button == "stopping: laser off, landing" and not enabled and "confirmed" in status
    finally:
        proxy.close()


def test_stop_retries_through_transient_failures_and_shows_stopping_only_once_confirmed(
    browser: webdriver.Chrome,
) -> None:
    proxy = Proxy(["drop", "502"])
    try:
        browser.get(proxy.url)
        seen: list[str] = []
        browser.find_element(By.ID, "stop").click()
        deadline = time.monotonic() + 20
        while "stopping" not in _texts(browser)[0]:
            assert time.monotonic() < deadline, "never confirmed"
            text = _texts(browser)[0]  # read before the posts: "stopping" may only follow an "ok"
            if proxy.posts[-1:] != ["ok"]:
                seen.append(text)
            time.sleep(0.02)
        assert proxy.posts == ["drop", "502", "ok"] and proxy.stop_requested
        assert not [text for text in seen if "stopping" in text], "stopping shown before the pilot confirmed"
        assert browser.execute_script("return window.liveView.stopAttempts") == 3
    finally:
        proxy.close()
