"""A real headless Chromium driven over the Chrome DevTools protocol, for the viewer's tests.

Only Python: Chromium (the Debian ``chromium`` package; ``.ci/run`` installs it) is started with
``--remote-debugging-port=0``; the port it picked is read from ``DevToolsActivePort`` in its profile
folder, and the page is driven over a websocket (the ``websockets`` package, which viser needs anyway).
A :class:`PageVisit` keeps what a person would see: the console errors and uncaught exceptions, and a
PNG screenshot.
"""

from __future__ import annotations

import base64
import contextlib
import itertools
import json
import os
import shutil
import subprocess
import tempfile
import time
import urllib.request
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome")
_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--enable-unsafe-swiftshader",  # WebGL in software: viser draws with three.js
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-dev-shm-usage",
    "--remote-debugging-port=0",
    "--remote-allow-origins=*",
]


def chromium_or_skip() -> str:
    """The browser's path; skip with the reason where there is none, but fail under CI (CI=true must run these)."""
    for name in CHROMIUM_NAMES:
        path = shutil.which(name)
        if path:
            return path
    reason = "no Chromium on PATH: install it with `apt-get install chromium` (as root; .ci/run does)"
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(f"CI must run the browser tests: {reason}")
    pytest.skip(reason)


@dataclass
class PageVisit:
    """What a page did while it was open: console errors, uncaught exceptions, and the screenshot taken at the end."""

    url: str
    errors: list[str] = field(default_factory=list)
    screenshot: bytes = b""


class Chromium:
    """One headless Chromium process; ``visit(url)`` opens a page, waits, and returns a :class:`PageVisit`."""

    def __init__(self, path: str, width: int = 1000, height: int = 700) -> None:
        self._profile = tempfile.mkdtemp(prefix="quasistatic-chromium-")
        self._width, self._height = width, height
        self._process = subprocess.Popen(
            [path, *_FLAGS, f"--user-data-dir={self._profile}", f"--window-size={width},{height}", "about:blank"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        self._port = self._debugging_port()
        self._ids = itertools.count(1)

    def _debugging_port(self, timeout: float = 30.0) -> int:
        marker = Path(self._profile) / "DevToolsActivePort"
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if marker.exists() and marker.read_text().strip():
                return int(marker.read_text().splitlines()[0])
            if self._process.poll() is not None:
                raise RuntimeError(f"chromium exited with code {self._process.returncode} before it listened")
            time.sleep(0.1)
        raise RuntimeError("chromium did not open its debugging port")

    def visit(self, url: str, settle: float = 6.0) -> PageVisit:
        """Open ``url`` in a new tab, collect console errors for ``settle`` seconds, screenshot, close the tab."""
        from websockets.sync.client import connect

        target = _json(f"http://127.0.0.1:{self._port}/json/new?about:blank", method="PUT")
        visit = PageVisit(url)
        with connect(target["webSocketDebuggerUrl"], max_size=64 * 1024 * 1024) as socket:
            for method in ("Page.enable", "Runtime.enable", "Log.enable"):
                self._call(socket, method, {}, visit)
            self._call(
                socket,
                "Emulation.setDeviceMetricsOverride",
                {"width": self._width, "height": self._height, "deviceScaleFactor": 1, "mobile": False},
                visit,
            )
            self._call(socket, "Page.navigate", {"url": url}, visit)
            deadline = time.monotonic() + settle
            while time.monotonic() < deadline:
                self._event(socket, visit, deadline - time.monotonic())
            shot = self._call(socket, "Page.captureScreenshot", {"format": "png"}, visit)
            visit.screenshot = base64.b64decode(shot["data"])
        urllib.request.urlopen(f"http://127.0.0.1:{self._port}/json/close/{target['id']}", timeout=30).close()
        return visit

    def _call(self, socket: Any, method: str, params: dict[str, Any], visit: PageVisit) -> dict[str, Any]:
        ident = next(self._ids)
        socket.send(json.dumps({"id": ident, "method": method, "params": params}))
        while True:
            message = json.loads(socket.recv(timeout=60))
            if message.get("id") == ident:
                if "error" in message:
                    raise RuntimeError(f"{method}: {message['error']}")
                result: dict[str, Any] = message.get("result", {})
                return result
            _record(message, visit)

    def _event(self, socket: Any, visit: PageVisit, timeout: float) -> None:
        with contextlib.suppress(TimeoutError):
            _record(json.loads(socket.recv(timeout=max(timeout, 0.01))), visit)

    def close(self) -> None:
        self._process.terminate()
        try:
            self._process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self._process.kill()
            self._process.wait()
        shutil.rmtree(self._profile, ignore_errors=True)


def _record(message: dict[str, Any], visit: PageVisit) -> None:
    """Keep console errors, uncaught exceptions and error log entries (failed loads included)."""
    method, params = message.get("method"), message.get("params", {})
    if method == "Runtime.consoleAPICalled" and params.get("type") in ("error", "assert"):
        visit.errors.append("console: " + " ".join(str(a.get("value", a.get("description", ""))) for a in params.get("args", [])))
    elif method == "Runtime.exceptionThrown":
        details = params.get("exceptionDetails", {})
        visit.errors.append("exception: " + str(details.get("exception", {}).get("description", details.get("text", ""))))
    elif method == "Log.entryAdded" and params.get("entry", {}).get("level") == "error":
        entry = params["entry"]
        visit.errors.append(f"log ({entry.get('source')}): {entry.get('text')} {entry.get('url', '')}".strip())


def _json(url: str, method: str = "GET") -> Any:
    request = urllib.request.Request(url, method=method)
    with urllib.request.urlopen(request, timeout=30) as response:
        return json.loads(response.read().decode() or "null")
