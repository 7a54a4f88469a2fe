"""The design page in a real browser: headless Chromium (Debian's ``chromium``), driven over the DevTools protocol,
loads ``/`` from the suite's service, moves an actuator's slider, and the test checks that the configuration shown
is the library's forward kinematics at the new actuator value and that the 3-D view's pixels changed; then the page's
two jobs run (every assembly mode there: as many as :func:`pkm.assembly_modes` finds; a workspace map) and another
design is built from the parameters panel; no console error or exception occurs (skipped without Chromium, a failure when ``PKM_REQUIRE_BROWSER`` is set, as
``tests/test_viz_browser.py``)."""

from __future__ import annotations

import base64
import io
import json
import re
import subprocess
import time

import httpx
import numpy as np

import pkm
from tests.serve.conftest import TOKEN
from tests.test_viz_browser import chromium


class DevTools:
    """A page of a headless Chromium over the DevTools protocol; :attr:`errors` collects console errors and uncaught
    exceptions."""

    def __init__(self, folder):
        from websockets.sync.client import connect

        self.proc = subprocess.Popen(
            [chromium(), "--headless", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
             "--disable-background-networking", "--window-size=1000,700", "--remote-debugging-port=0",
             f"--user-data-dir={folder}", "about:blank"], stderr=subprocess.PIPE, text=True)
        port = None
        deadline = time.monotonic() + 30
        while port is None and time.monotonic() < deadline:
            line = self.proc.stderr.readline()
            m = re.search(r"DevTools listening on ws://127\.0\.0\.1:(\d+)/", line)
            port = int(m.group(1)) if m else None
        assert port, "chromium printed no DevTools address"
        pages = [t for t in httpx.get(f"http://127.0.0.1:{port}/json/list").json() if t["type"] == "page"]
        self._connection = connect(pages[0]["webSocketDebuggerUrl"], max_size=2**26)
        self.ws = self._connection.__enter__()
        self.next_id, self.errors = 0, []
        for domain in ("Runtime", "Log", "Page"):
            self.call(f"{domain}.enable")

    def call(self, method: str, **params):
        self.next_id += 1
        self.ws.send(json.dumps({"id": self.next_id, "method": method, "params": params}))
        while True:
            message = json.loads(self.ws.recv(timeout=60))
            if message.get("id") == self.next_id:
                assert "error" not in message, message
                return message.get("result", {})
            self._event(message)

    def _event(self, message: dict) -> None:
        method, params = message.get("method"), message.get("params", {})
        if method == "Runtime.consoleAPICalled" and params.get("type") == "error":
            self.errors.append(" ".join(str(a.get("value", a.get("description"))) for a in params.get("args", [])))
        elif method == "Runtime.exceptionThrown":
            self.errors.append(params["exceptionDetails"].get("text", "exception"))
        elif method == "Log.entryAdded" and params["entry"].get("level") == "error":
            self.errors.append(params["entry"].get("text", ""))

    def evaluate(self, expression: str):
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        return result["result"].get("value")

    def wait(self, expression: str, timeout: float = 60.0):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            value = self.evaluate(expression)
            if value:
                return value
            time.sleep(0.1)
        raise AssertionError(f"waited {timeout} s for {expression}: {self.evaluate('JSON.stringify(pkmState)')}")

    def screenshot(self) -> np.ndarray:
        import matplotlib.image as mimage

        png = base64.b64decode(self.call("Page.captureScreenshot", format="png")["data"])
        return mimage.imread(io.BytesIO(png), format="png")[..., :3]

    def close(self) -> None:
        self._connection.__exit__(None, None, None)
        self.proc.kill()
        self.proc.wait(timeout=30)


def test_moving_a_slider_moves_the_mechanism(service, tmp_path):
    browser = DevTools(tmp_path)
    try:
        browser.call("Page.navigate", url=f"{service.url}/?token={TOKEN}&model=delta")
        browser.wait("window.pkmState && pkmState.updates >= 1 && !pkmState.busy")
        time.sleep(0.5)  # (the view renders on its next animation frame)
        before = browser.screenshot()
        q0 = np.array(browser.evaluate("pkmState.q"))
        target = browser.evaluate("(function () { const s = document.getElementById('qa-0');"
                                  " s.value = parseFloat(s.min) + 0.8 * (s.max - s.min);"
                                  " s.dispatchEvent(new Event('input')); return parseFloat(s.value); })()")
        browser.wait("pkmState.updates >= 2 && !pkmState.busy && !pkmState.pending")
        time.sleep(0.5)
        after = browser.screenshot()
        import matplotlib.image as mimage

        mimage.imsave(tmp_path / "page.png", after)
        q1 = np.array(browser.evaluate("pkmState.q"))
        updates = browser.evaluate("pkmState.updates")
        z = browser.evaluate("(function () { const s = document.getElementById('y-2');"  # (a task slider: the IK)
                             " s.value = parseFloat(s.value) - 0.02; s.dispatchEvent(new Event('input'));"
                             " return parseFloat(s.value); })()")
        browser.wait(f"pkmState.updates > {updates} && !pkmState.busy")
        y2 = browser.evaluate("pkmState.y")
        browser.evaluate("document.getElementById('modes-button').click()")  # (the assembly modes job)
        modes = browser.wait("pkmState.modes && pkmState.modes.length")
        browser.evaluate("document.getElementById('map-button').click()")  # (the map job)
        nodes = browser.wait("pkmState.map && pkmState.map.nodes")
        updates = browser.evaluate("pkmState.updates")
        browser.evaluate("document.getElementById('param-R').value = 0.16;"  # (another design, built and shown)
                         " document.getElementById('params-button').click()")
        variant = browser.wait(f"pkmState.model.startsWith('delta@') && pkmState.updates > {updates} && pkmState.model")
        assert browser.evaluate("pkmState.errors") == [] and browser.errors == []
    finally:
        browser.close()
    delta = pkm.load("delta")
    qa = delta.actuated_q(q0)
    qa[0] = target
    assert np.abs(q1 - pkm.close_loops(delta, qa, q0).q).max() <= 1e-9 and np.abs(q1 - q0).max() > 0.05
    assert modes == len(pkm.assembly_modes(delta, qa).modes) and nodes > 0
    assert abs(y2[2] - z) <= 1e-9  # (the pose shown reaches the task slider's z)
    assert httpx.get(f"{service.url}/models/{variant}", headers={"authorization": f"Bearer {TOKEN}"}).json()["kind"] \
        == "variant"
    view = slice(None), slice(320, None)  # (the 3-D view, right of the side panel)
    changed = np.abs(after[view] - before[view]).max(axis=-1) > 0.1
    assert changed.mean() > 0.002, changed.mean()
