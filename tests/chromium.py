"""Headless Chromium driven over the DevTools protocol on a pipe (standard library only), for the report tests."""

from __future__ import annotations

import base64
import json
import os
import select
import shutil
import subprocess
import time
from pathlib import Path

import pytest

CHROMIUM = shutil.which("chromium")
VERDICT = """JSON.stringify({
  readyState: document.readyState,
  title: document.title,
  tables: document.querySelectorAll("table").length,
  images: Array.from(document.images, image => image.complete ? image.naturalWidth : 0),
})"""


class _Chromium:
    """Headless Chromium driven over the DevTools protocol on a pipe (``--remote-debugging-pipe``).

    Chromium reads commands on its file descriptor 3 and writes replies and
    events on 4, as NUL-terminated JSON; every event is kept in ``events``.
    """

    def __init__(self, executable: str, profile: Path) -> None:
        self._executable = executable
        self._profile = profile
        self._buffer = b""
        self._next_id = 0
        self._session = ""
        self.events: list[dict] = []

    def __enter__(self) -> _Chromium:
        commands, self._to_browser = os.pipe()
        self._from_browser, replies = os.pipe()
        flags = ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync", "--disable-extensions", "--remote-debugging-pipe",
                 f"--user-data-dir={self._profile}", "about:blank"]  # fmt: skip
        shell = 'exec "$0" "$@" 3<&0 4>&1 </dev/null >/dev/null'
        self._process = subprocess.Popen(
            ["sh", "-c", shell, self._executable, *flags], stdin=commands, stdout=replies, stderr=subprocess.DEVNULL
        )
        os.close(commands)
        os.close(replies)
        try:
            target = self.call("Target.createTarget", url="about:blank")["targetId"]
            self._session = self.call("Target.attachToTarget", targetId=target, flatten=True)["sessionId"]
            for domain in ("Page", "Runtime", "Log", "Network"):
                self.call(f"{domain}.enable", session=True)
        except BaseException:
            self.__exit__()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        try:
            self.call("Browser.close")
        except (OSError, EOFError, TimeoutError, RuntimeError):
            pass
        try:
            self._process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self._process.kill()
            self._process.wait()
        os.close(self._to_browser)
        os.close(self._from_browser)

    def call(self, method: str, session: bool = False, **params: object) -> dict:
        """Send a command and return its result (events that arrive meanwhile are kept)."""
        self._next_id += 1
        message = {"id": self._next_id, "method": method, "params": params}
        if session:
            message["sessionId"] = self._session
        os.write(self._to_browser, json.dumps(message).encode() + b"\0")
        while True:
            reply = self._receive()
            if reply.get("id") == self._next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)

    def wait_for(self, method: str, timeout: float = 30.0) -> None:
        """Wait until an event ``method`` has arrived."""
        deadline = time.monotonic() + timeout
        while not any(event.get("method") == method for event in self.events):
            self.events.append(self._receive(deadline - time.monotonic()))

    def _receive(self, timeout: float = 30.0) -> dict:
        deadline = time.monotonic() + timeout
        while b"\0" not in self._buffer:
            ready, _, _ = select.select([self._from_browser], [], [], max(0.0, deadline - time.monotonic()))
            if not ready:
                raise TimeoutError("no answer from chromium")
            chunk = os.read(self._from_browser, 1 << 16)
            if not chunk:
                raise EOFError("chromium closed the pipe")
            self._buffer += chunk
        message, _, self._buffer = self._buffer.partition(b"\0")
        return json.loads(message)


def _problems(events: list[dict], page_url: str) -> list[str]:
    """Errors, failed loads and requests for anything but the page itself and data: URIs."""
    problems = []
    for event in events:
        method, params = event.get("method"), event.get("params", {})
        if method == "Runtime.exceptionThrown":
            problems.append(f"exception: {params['exceptionDetails'].get('text')}")
        elif method == "Runtime.consoleAPICalled" and params["type"] in ("error", "assert"):
            problems.append(f"console.{params['type']}: {params['args']}")
        elif method == "Log.entryAdded" and params["entry"]["level"] == "error":
            problems.append(f"log: {params['entry']['text']}")
        elif method == "Network.loadingFailed":
            problems.append(f"load failed: {params['errorText']}")
        elif method == "Network.requestWillBeSent" and params["request"]["url"] != page_url and not params["request"]["url"].startswith("data:"):
            problems.append(f"request: {params['request']['url']}")
    return problems


def render_in_chromium(html: Path, screenshot: Path, executable: str) -> tuple[dict, list[str]]:
    """Load ``html`` in headless Chromium at 1280×2000: the page's verdict, the problems seen, and a screenshot."""
    with _Chromium(executable, screenshot.parent / "chromium-profile") as browser:
        browser.call("Emulation.setDeviceMetricsOverride", session=True, width=1280, height=2000, deviceScaleFactor=1, mobile=False)
        browser.call("Page.navigate", session=True, url=html.as_uri())
        browser.wait_for("Page.loadEventFired")
        verdict = browser.call("Runtime.evaluate", session=True, expression=VERDICT, returnByValue=True)["result"]["value"]
        shot = browser.call("Page.captureScreenshot", session=True, format="png")["data"]
        screenshot.write_bytes(base64.b64decode(shot))
        return json.loads(verdict), _problems(browser.events, html.as_uri())




def require_chromium() -> str:
    """The chromium executable; skip without it, except under CI (which must install it: .ci/run does)."""
    if CHROMIUM is None:
        if os.environ.get("CI"):
            pytest.fail("chromium is missing: CI must install it (.ci/run does)")
        pytest.skip("chromium is not installed")
    return CHROMIUM
