"""Headless Chromium with the outside network off, over the DevTools protocol: every request a page makes recorded.

Used by ``tests/serve/test_offline.py`` (the service's pages), ``tests/serve/test_page.py`` (the design page),
``tests/test_viz_browser.py`` (pkm.viz's pictures) and ``tools/offline_site.py`` (every page of the docs site); the
tests share one Chromium a session (:class:`Shared`, the fixture ``offline_browser`` of ``tests/conftest.py``: starting
one costs about 2 s of CPU), each test its own page, loaded afresh. Outside traffic is blocked twice: every host name but ``127.0.0.1`` resolves to nothing
(``--host-resolver-rules``), and every request that is not to the loopback goes to a proxy that is not there
(``--proxy-server`` on a closed port of 127.0.0.1; Chromium sends loopback requests directly), so that an address
written as a number fails too. The pages' requests are recorded (the Network domain), whether they succeeded or not,
as are console errors, uncaught exceptions and failed loads; the pages' workers (attached as they start) are
watched the same way.
"""

from __future__ import annotations

import base64
import io
import json
import os
import re
import shutil
import signal
import subprocess
import threading
import time
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

import numpy as np

#: The schemes of URLs that stay inside the browser.
LOCAL_SCHEMES = ("data", "blob", "about", "chrome", "devtools")


def leaves_the_machine(url: str) -> bool:
    """Whether a request for ``url`` goes anywhere but 127.0.0.1 (or stays inside the browser: ``data:`` ...)."""
    parts = urlsplit(url)
    return parts.scheme not in LOCAL_SCHEMES and parts.hostname != "127.0.0.1"


class OfflineBrowser:
    """One headless Chromium page with the outside network off (see the module doc), its viewport ``width`` by
    ``height`` pixels (as :meth:`screenshot` shows it).

    :attr:`requests` holds the URL of every request since the last :meth:`load`, :attr:`errors` the console errors,
    uncaught exceptions and failed requests (with their URL and reason).
    """

    def __init__(self, chromium: str, folder: Path, width: int = 1200, height: int = 900, cache: bool = False):
        from websockets.sync.client import connect

        self.proc = subprocess.Popen(
            [chromium, "--headless", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
             "--disable-background-networking", "--disable-component-update", "--no-first-run",
             "--host-resolver-rules=MAP * ~NOTFOUND , EXCLUDE 127.0.0.1", "--proxy-server=http://127.0.0.1:9",
             f"--window-size={width},{height}", "--remote-debugging-port=0", f"--user-data-dir={folder}",
             "about:blank"], stderr=subprocess.PIPE, text=True, start_new_session=True)
        try:
            port = None
            deadline = time.monotonic() + 30
            while port is None and time.monotonic() < deadline:
                line = self.proc.stderr.readline() if self.proc.stderr else ""
                m = re.search(r"DevTools listening on ws://127\.0\.0\.1:(\d+)/", line)
                port = int(m.group(1)) if m else None
                if not line and self.proc.poll() is not None:
                    break
            if port is None:
                raise RuntimeError("chromium printed no DevTools address")
            threading.Thread(target=self.proc.stderr.read, daemon=True).start()  # (drained: never a full pipe)
            import httpx

            with httpx.Client(trust_env=False) as http:  # (no proxy from the environment for the loopback)
                pages = [t for t in http.get(f"http://127.0.0.1:{port}/json/list").json() if t["type"] == "page"]
            self._connection = connect(pages[0]["webSocketDebuggerUrl"], max_size=2**26, proxy=None)
            self.ws = self._connection.__enter__()
        except BaseException:
            self._stop()
            raise
        self.next_id, self._sent = 0, 10**9  # (commands awaited; commands sent to workers, not awaited)
        self.requests: list[str] = []
        self._urls: dict[str, str] = {}
        self._pending: set[str] = set()
        self._workers: set[str] = set()
        self.errors: list[str] = []
        self._loaded = False
        for domain in ("Runtime", "Log", "Page", "Network"):
            self.call(f"{domain}.enable")
        self.configure(width, height, cache)
        self.call("Target.setAutoAttach", autoAttach=True, waitForDebuggerOnStart=False, flatten=True)

    def configure(self, width: int = 1200, height: int = 900, cache: bool = False) -> None:
        """The page's viewport ``width`` by ``height`` pixels, and its cache on (emptied) or off, from now on."""
        # (no cache: every page's requests go to the network, where they are seen; a cached file was seen once)
        self.call("Network.setCacheDisabled", cacheDisabled=not cache)
        self.call("Network.clearBrowserCache")
        # (the window's size is not the page's: a headless window keeps some of it for itself)
        self.call("Emulation.setDeviceMetricsOverride", width=width, height=height, deviceScaleFactor=1, mobile=False)

    def __enter__(self) -> OfflineBrowser:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def call(self, method: str, **params: Any) -> dict:
        """A DevTools command's result (events arriving meanwhile are recorded)."""
        self.next_id += 1
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            message = json.loads(self.ws.recv(timeout=60))
            if message.get("id") == self.next_id:
                if "error" in message:
                    raise RuntimeError(f"{method}: {message['error']}")
                return message.get("result", {})
            self._event(message)

    def _event(self, message: dict) -> None:
        method, params = message.get("method"), message.get("params", {})
        if method == "Target.attachedToTarget":  # (a worker: its requests, console and exceptions recorded too)
            self._workers.add(params["targetInfo"].get("url", ""))  # (started: its script came, said or not)
            for domain in ("Network", "Runtime"):
                self._sent += 1
                self.ws.send(json.dumps({"id": self._sent, "method": f"{domain}.enable",
                                         "sessionId": params["sessionId"]}))
        elif method == "Network.requestWillBeSent":
            self.requests.append(params["request"]["url"])
            self._urls[params["requestId"]] = params["request"]["url"]
            if urlsplit(params["request"]["url"]).scheme not in LOCAL_SCHEMES:  # (data: and blob: never finish)
                self._pending.add(params["requestId"])
        elif method in ("Network.loadingFinished", "Network.responseReceived"):  # (answered: no longer awaited)
            self._pending.discard(params["requestId"])
        elif method == "Network.loadingFailed":
            self._pending.discard(params["requestId"])
            if not params.get("canceled"):
                url = self._urls.get(params["requestId"], "?")
                self.errors.append(f"request failed ({params.get('errorText')}): {url}")
        elif method == "Runtime.consoleAPICalled" and params.get("type") == "error":
            self.errors.append(" ".join(str(a.get("value", a.get("description"))) for a in params.get("args", [])))
        elif method == "Runtime.exceptionThrown":
            details = params["exceptionDetails"]
            self.errors.append(details.get("exception", {}).get("description") or details.get("text", "exception"))
        elif method == "Log.entryAdded" and params["entry"].get("level") == "error":
            self.errors.append(f"{params['entry'].get('text', '')} {params['entry'].get('url', '')}".strip())
        elif method == "Page.loadEventFired":
            self._loaded = True

    def load(self, url: str, timeout: float = 30.0) -> None:
        """Navigate to ``url`` and wait for its load event; :attr:`requests` and :attr:`errors` start afresh."""
        self.requests, self.errors, self._urls, self._pending, self._loaded = [], [], {}, set(), False
        result = self.call("Page.navigate", url=url)
        if result.get("errorText"):
            raise RuntimeError(f"{url}: {result['errorText']}")
        deadline = time.monotonic() + timeout
        while not self._loaded:
            if time.monotonic() > deadline:
                raise TimeoutError(f"{url}: no load event in {timeout} s")
            self._event(json.loads(self.ws.recv(timeout=max(deadline - time.monotonic(), 0.01))))

    def evaluate(self, expression: str) -> Any:
        """The value of a JavaScript expression in the page (promises awaited)."""
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in result:
            raise RuntimeError(f"{expression}: {result['exceptionDetails'].get('text')}")
        return result["result"].get("value")

    def wait(self, expression: str, timeout: float = 30.0) -> Any:
        """The first truthy value of ``expression``, polled every 50 ms for at most ``timeout`` seconds."""
        deadline = time.monotonic() + timeout
        while True:
            value = self.evaluate(expression)
            if value or time.monotonic() > deadline:
                return value
            time.sleep(0.05)

    def frames(self, n: int = 2) -> None:
        """Return once the page has drawn ``n`` more animation frames (a page that draws on its next frame, such as
        meshcat's viewer, has drawn what it was given before the call)."""
        self.evaluate(f"new Promise(r => {{ let n = {n}; const f = () => --n > 0 ? requestAnimationFrame(f) : r(); "
                      "requestAnimationFrame(f); })")

    def screenshot(self) -> np.ndarray:
        """The page as it shows now: an (height, width, 3) RGB array in [0, 1]."""
        import matplotlib.image as mimage

        png = base64.b64decode(self.call("Page.captureScreenshot", format="png")["data"])
        return mimage.imread(io.BytesIO(png), format="png")[..., :3]

    def settle(self, quiet: float = 0.25, timeout: float = 10.0) -> None:
        """Record events until no request is pending and none was sent or answered for ``quiet`` seconds (at most
        ``timeout``)."""
        now = time.monotonic()
        deadline, last = now + timeout, now
        while now < deadline:
            waiting = [i for i in self._pending if self._urls[i] not in self._workers]
            if not waiting and now - last >= quiet:
                return
            try:
                message = json.loads(self.ws.recv(timeout=quiet))
            except TimeoutError:
                message = {}
            self._event(message)
            now = time.monotonic()
            if message.get("method", "").startswith("Network."):
                last = now

    def outside(self) -> list[str]:
        """The URLs of this page's requests that were to leave the machine."""
        return [u for u in self.requests if leaves_the_machine(u)]

    def close(self) -> None:
        """Chromium stopped: asked (SIGTERM: it ends its renderers and lets go of its profile folder), then killed
        with every process it started that is left."""
        try:
            self._connection.__exit__(None, None, None)
        finally:
            self._stop()

    def _stop(self) -> None:
        self.proc.terminate()
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            pass
        # Its helpers (network service, renderers) can outlive it and still write its profile folder (a CI run's
        # temporary folder failed to go: 'Cache_Data' not empty): the whole group (its own: start_new_session) is
        # killed, and awaited until none is left (5 s at most: a zombie an unreaping init keeps stays in the group).
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline:
            try:
                os.killpg(self.proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                break
            if self.proc.poll() is None:
                self.proc.wait(timeout=30)
            if not _running_in_group(self.proc.pid):  # (zombies only: nothing writes any more; waited 5 s before)
                break
            time.sleep(0.05)


def _running_in_group(pgid: int) -> bool:
    """Whether a process of group ``pgid`` other than a zombie is left (Linux's ``/proc``; elsewhere True, so that the
    caller waits out its deadline as before)."""
    if not os.path.isdir("/proc/self"):
        return True
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as fh:
                fields = fh.read().rsplit(")", 1)[1].split()  # (after the command name, which may hold spaces)
        except OSError:
            continue
        if int(fields[2]) == pgid and fields[0] != "Z":  # (fields: state, ppid, pgrp, ...)
            return True
    return False


def chromium() -> str:
    """The Chromium executable; skip the test (or fail it when ``PKM_REQUIRE_BROWSER`` is set) if there is none."""
    import pytest

    exe = shutil.which("chromium") or ("/usr/bin/chromium" if Path("/usr/bin/chromium").exists() else None)
    if exe is None:
        if os.environ.get("PKM_REQUIRE_BROWSER", "") not in ("", "0"):
            pytest.fail("PKM_REQUIRE_BROWSER is set but chromium is not installed (Debian package 'chromium')")
        pytest.skip("chromium is not installed; set PKM_REQUIRE_BROWSER=1 to make this a failure")
    return exe


class Shared:
    """One :class:`OfflineBrowser` for many tests: ``shared(width, height, cache)`` is it, on a blank page (loaded:
    nothing of the last test's page left to come), configured (:meth:`OfflineBrowser.configure`); started at the
    first call, and again if it has stopped. :meth:`close` stops it."""

    def __init__(self, folder: Path):
        self.folder, self.browser, self.started = folder, None, 0

    def __call__(self, width: int = 1200, height: int = 900, cache: bool = False) -> OfflineBrowser:
        if self.browser is not None:
            try:
                if self.browser.proc.poll() is not None:
                    raise RuntimeError("chromium stopped")
                self.browser.load("about:blank")
                self.browser.configure(width, height, cache)
                return self.browser
            except Exception:  # (a test left it broken, its connection closed ...: another one, for this test)
                self.close()
        self.started += 1
        self.browser = OfflineBrowser(chromium(), self.folder / f"profile-{self.started}", width, height, cache)
        return self.browser

    def close(self) -> None:
        if self.browser is not None:
            browser, self.browser = self.browser, None
            browser.close()
