"""A headless browser for the tests of ``report.html``: Debian's Chromium driven by Selenium.

``tests/test_html_report.py`` and ``tests/benchmarks/test_bench_html_report.py`` share it. The
browser is ``/usr/bin/chromium`` with ``/usr/bin/chromedriver`` (Debian's ``chromium`` and
``chromium-driver`` packages; ``.ci/run`` installs them), started headless with no network
activity of its own, in a fresh profile. Where the browser, its driver or Selenium is missing,
:data:`needs_browser` skips the test and says which.
"""
from __future__ import annotations

import contextlib
import shutil
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

CHROMIUM = Path("/usr/bin/chromium")
CHROMEDRIVER = Path("/usr/bin/chromedriver")
FLAGS = ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--no-first-run", "--disable-sync", "--window-size=1400,1000")


def browser_missing() -> str | None:
    """Why the browser tests cannot run here, or None."""
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "selenium is not installed (pip install selenium, or the project's test extra)"
    for path, package in ((CHROMIUM, "chromium"), (CHROMEDRIVER, "chromium-driver")):
        if not path.exists():
            return f"{path} is missing (Debian package {package}: apt-get install chromium chromium-driver)"
    return None


needs_browser = pytest.mark.skipif(browser_missing() is not None, reason=str(browser_missing()))


@contextlib.contextmanager
def chromium() -> Iterator[Any]:
    """A headless Chromium (a Selenium ``WebDriver``) that keeps the browser console's messages."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    profile = tempfile.mkdtemp(prefix="slewbench-chromium-")
    options = webdriver.ChromeOptions()
    options.binary_location = str(CHROMIUM)
    for flag in (*FLAGS, f"--user-data-dir={profile}"):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(str(CHROMEDRIVER)), options=options)
    try:
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


def open_page(driver: Any, path: Path, timeout: float = 60.0) -> list[dict]:
    """Load a report, wait until its script says every figure is drawn, and return the console's
    messages (``level``, ``message``)."""
    driver.get(path.resolve().as_uri())
    deadline = time.monotonic() + timeout
    while not driver.execute_script("return !!(window.slewbench && window.slewbench.drawn)"):
        assert time.monotonic() < deadline, "the figures were not drawn in time"
        time.sleep(0.05)
    return driver.get_log("browser")


def errors_in(log: list[dict]) -> list[dict]:
    """The console's errors (level ``SEVERE``: uncaught exceptions, failed loads, ``console.error``)."""
    return [entry for entry in log if entry["level"] == "SEVERE"]


def load_times(driver: Any) -> dict[str, float]:
    """Times of the page last opened, from navigation start [s] (the Performance API):
    ``load`` the end of the load event, ``script`` when the report's script started (plotly.js parsed
    and run), ``drawn`` when every figure was drawn."""
    return driver.execute_script(
        "var n = performance.getEntriesByType('navigation')[0], out = {load: n.loadEventEnd / 1000};"
        "performance.getEntriesByType('mark').forEach(function (m) {"
        "  out[m.name.replace('slewbench-', '')] = m.startTime / 1000; });"
        "return out;")
