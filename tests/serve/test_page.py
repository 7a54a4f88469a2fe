"""The design page in a real browser: headless Chromium (Debian's ``chromium``), driven over the DevTools protocol,
loads ``/`` from the suite's service, moves an actuator's slider, and the test checks that the configuration shown
is the library's forward kinematics at the new actuator value and that the 3-D view's pixels changed; then the page's
two jobs run (every assembly mode there: as many as :func:`pkm.assembly_modes` finds; a workspace map) and another
design is built from the parameters panel; no console error, exception or failed request occurs, with the outside
network off (:class:`tests.browser.OfflineBrowser`; skipped without Chromium, a failure when ``PKM_REQUIRE_BROWSER``
is set, as ``tests/test_viz_browser.py``)."""

from __future__ import annotations

import numpy as np

import pkm
from tests import http
from tests.browser import OfflineBrowser
from tests.serve.conftest import TOKEN


def _wait(browser: OfflineBrowser, expression: str, timeout: float = 60.0):
    """``browser.wait``, failing with the page's state when ``expression`` stays falsy."""
    value = browser.wait(expression, timeout)
    assert value, f"waited {timeout} s for {expression}: {browser.evaluate('JSON.stringify(pkmState)')}"
    return value


def test_moving_a_slider_moves_the_mechanism(service, offline_browser, tmp_path):
    browser = offline_browser(1000, 700, cache=True)
    browser.load(f"{service.url}/?token={TOKEN}&model=delta")
    _wait(browser, "window.pkmState && pkmState.updates >= 1 && !pkmState.busy")
    browser.frames()  # (the view draws on its next animation frame)
    before = browser.screenshot()
    q0 = np.array(browser.evaluate("pkmState.q"))
    target = browser.evaluate("(function () { const s = document.getElementById('qa-0');"
                              " s.value = parseFloat(s.min) + 0.8 * (s.max - s.min);"
                              " s.dispatchEvent(new Event('input')); return parseFloat(s.value); })()")
    _wait(browser, "pkmState.updates >= 2 && !pkmState.busy && !pkmState.pending")
    browser.frames()
    after = browser.screenshot()
    import matplotlib.image as mimage

    mimage.imsave(tmp_path / "page.png", after)
    q1 = np.array(browser.evaluate("pkmState.q"))
    updates = browser.evaluate("pkmState.updates")
    z = browser.evaluate("(function () { const s = document.getElementById('y-2');"  # (a task slider: the IK)
                         " s.value = parseFloat(s.value) - 0.02; s.dispatchEvent(new Event('input'));"
                         " return parseFloat(s.value); })()")
    _wait(browser, f"pkmState.updates > {updates} && !pkmState.busy")
    y2 = browser.evaluate("pkmState.y")
    browser.evaluate("document.getElementById('modes-button').click()")  # (the assembly modes job)
    modes = _wait(browser, "pkmState.modes && pkmState.modes.length")
    browser.evaluate("document.getElementById('map-button').click()")  # (the map job)
    nodes = _wait(browser, "pkmState.map && pkmState.map.nodes")
    updates = browser.evaluate("pkmState.updates")
    browser.evaluate("document.getElementById('param-R').value = 0.16;"  # (another design, built and shown)
                     " document.getElementById('params-button').click()")
    variant = _wait(browser, f"pkmState.model.startsWith('delta@') && pkmState.updates > {updates} && pkmState.model")
    assert browser.evaluate("pkmState.errors") == [] and browser.errors == []
    delta = pkm.load("delta")
    qa = delta.actuated_q(q0)
    qa[0] = target
    assert np.abs(q1 - pkm.close_loops(delta, qa, q0).q).max() <= 1e-9 and np.abs(q1 - q0).max() > 0.05
    assert modes == len(pkm.assembly_modes(delta, qa).modes) and nodes > 0
    assert abs(y2[2] - z) <= 1e-9  # (the pose shown reaches the task slider's z)
    assert http.get(f"{service.url}/models/{variant}", headers={"authorization": f"Bearer {TOKEN}"}).json()["kind"] \
        == "variant"
    view = slice(None), slice(320, None)  # (the 3-D view, right of the side panel)
    changed = np.abs(after[view] - before[view]).max(axis=-1) > 0.1
    assert changed.mean() > 0.002, changed.mean()
