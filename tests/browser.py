"""Headless Chromium for the report-page tests, driven through Selenium (WebDriver) and Debian's
``chromium-driver`` (``chromedriver``), which ``.ci/setup`` installs next to ``chromium``.

One browser serves a whole test session (``conftest.browser``).  Besides WebDriver's own calls
the helper reads Chromium's logs through the driver: the browser log (console errors, uncaught
exceptions, failed loads) and the performance log (every network request the page makes, so a
test can say that a page loads nothing but itself).  No network service is used: the driver
talks to Chromium over a local pipe chromedriver owns, and Selenium Manager (which could
download a driver) is kept offline and never needed, the driver's path being given.
"""
from __future__ import annotations

import base64
import json
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

#: the flags that work in CI containers (no sandbox, no GPU, no background network services)
FLAGS = ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-default-apps", "--disable-extensions", "--mute-audio", "--hide-scrollbars",
         "--disable-features=Translate,OptimizationHints,MediaRouter"]


def chromium_path() -> str | None:
    """The Chromium executable (Debian's ``chromium``), or None."""
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        found = shutil.which(name)
        if found:
            return found
    return None


def chromedriver_path() -> str | None:
    """The WebDriver server for that Chromium (Debian's ``chromium-driver``), or None."""
    return shutil.which("chromedriver")


def selenium_missing() -> str | None:
    """Why the browser cannot be started here (the package, the browser or the driver missing),
    or None."""
    try:
        import selenium  # noqa: F401 (only its presence is asked)
    except ImportError:
        return "selenium is not installed (pip install -e '.[test]')"
    if chromium_path() is None:
        return "no chromium on PATH (bash .ci/setup installs Debian's chromium)"
    if chromedriver_path() is None:
        return "no chromedriver on PATH (bash .ci/setup installs Debian's chromium-driver)"
    return None


class Browser:
    """One headless Chromium window; ``with Browser() as b: b.open(path) ...``."""

    def __init__(self, width: int = 1200, height: int = 900, timeout: float = 60.0) -> None:
        os.environ.setdefault("SE_OFFLINE", "true")   # Selenium Manager never goes online
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
        self._profile = tempfile.mkdtemp(prefix="driver_chromium_")
        opts = webdriver.ChromeOptions()
        opts.binary_location = chromium_path() or "chromium"
        for flag in [*FLAGS, f"--window-size={width},{height}", f"--user-data-dir={self._profile}"]:
            opts.add_argument(flag)
        opts.set_capability("goog:loggingPrefs", {"browser": "ALL", "performance": "ALL"})
        self.driver = webdriver.Chrome(service=Service(chromedriver_path() or "chromedriver"), options=opts)
        self.driver.set_page_load_timeout(timeout)
        self.driver.set_script_timeout(timeout)
        self.size(width, height)
        self._console: list[dict] = []
        self._requests: list[str] = []

    # ----------------------------------------------------------------- page
    def size(self, width: int, height: int) -> None:
        """Set the layout viewport to ``width`` x ``height`` CSS pixels (device scale 1)."""
        self.driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                                    {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False})

    def open(self, path: str | Path) -> None:
        """Load a file from disk and wait until it has loaded; the logs start afresh."""
        self._drain()
        self._console, self._requests = [], []
        self.driver.get(Path(path).resolve().as_uri())

    def eval(self, expression: str) -> Any:
        """Evaluate a JavaScript expression in the page and return its (JSON-able) value."""
        return self.driver.execute_script(f"return ({expression});")

    def wait(self, ms: int) -> None:
        """Let the page run for ``ms`` milliseconds (its timers fire)."""
        self.driver.execute_async_script(f"const done = arguments[arguments.length - 1]; setTimeout(done, {int(ms)});")

    def _drain(self) -> None:
        for entry in self.driver.get_log("browser"):
            self._console.append(entry)
        for entry in self.driver.get_log("performance"):
            msg = json.loads(entry["message"]).get("message", {})
            if msg.get("method") == "Network.requestWillBeSent":
                self._requests.append(msg["params"]["request"]["url"])

    def errors(self) -> list[str]:
        """Console errors, uncaught exceptions and failed loads since the page was opened."""
        self._drain()
        return [f"{e.get('source', '')}: {e.get('message', '')}" for e in self._console
                if e.get("level") in ("SEVERE", "ERROR")]

    def requests(self) -> list[str]:
        """Every URL the page asked for since it was opened (the page itself included)."""
        self._drain()
        return list(self._requests)

    def screenshot(self) -> bytes:
        """A PNG of the viewport."""
        return self.driver.get_screenshot_as_png()

    def pdf(self) -> bytes:
        """The page printed to PDF (the print style sheet applies)."""
        from selenium.webdriver.common.print_page_options import PrintOptions
        return base64.b64decode(self.driver.print_page(PrintOptions()))

    # ----------------------------------------------------------------- lifetime
    def close(self) -> None:
        try:
            self.driver.quit()
        finally:
            shutil.rmtree(self._profile, ignore_errors=True)

    def __enter__(self) -> Browser:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
