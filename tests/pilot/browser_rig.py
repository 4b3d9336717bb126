"""A real headless Chromium (Debian's chromium + chromium-driver, via Selenium) for the live view's tests."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

from selenium import webdriver
from selenium.webdriver.chrome.options import Options
from selenium.webdriver.chrome.service import Service

CHROMIUM, CHROMEDRIVER = "/usr/bin/chromium", "/usr/bin/chromedriver"
CHROMIUM_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync",
                  "--window-size=1200,900")


def chromium(profile: Path) -> webdriver.Chrome:
    assert Path(CHROMIUM).is_file() and Path(CHROMEDRIVER).is_file(), "make deps installs chromium + chromium-driver"
    options = Options()
    options.binary_location = CHROMIUM
    for flag in (*CHROMIUM_FLAGS, f"--user-data-dir={profile}"):
        options.add_argument(flag)
    return webdriver.Chrome(options=options, service=Service(executable_path=CHROMEDRIVER))


def browser_session(tmp_path: Path) -> Iterator[webdriver.Chrome]:
    """The body of a ``browser`` fixture: a fresh profile, quit and removed afterwards."""
    driver = chromium(tmp_path / "chromium-profile")
    try:
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(tmp_path / "chromium-profile", ignore_errors=True)
