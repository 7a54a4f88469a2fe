"""pkm.viz in a real browser: headless Chromium renders the Delta's snapshot, and the picture shows it.

The session's Chromium (:class:`tests.browser.OfflineBrowser`, the outside network off) shows each page, loaded
afresh, and its picture is taken once the page has drawn two frames after its load event (meshcat's viewer draws the
commands the page gave it on its next frame); no console error, exception or failed request may occur.

Skipped when Chromium is not installed, unless ``PKM_REQUIRE_BROWSER`` is set (CI sets it and
installs the Debian package ``chromium``): then a missing Chromium is a failure.

The screenshot is checked against the snapshot's own camera: each actuated joint's centre,
projected with meshcat's default perspective camera (75 degree vertical field of view, looking
at meshcat's origin, z up) from the position the snapshot gives it, must land on pixels of the
actuated colour; passive joints and the platform must show in their colours; the mechanism
must fill a good part of the picture, away from its edges. The hexapod's page shows its legend,
and each of its six legs in its own colour.
"""

from __future__ import annotations

import base64
import hashlib
import json
import re
from pathlib import Path

import matplotlib.colors as mcolors
import numpy as np
import pinocchio as pin
import pytest
import umsgpack

import pkm
from pkm import viz
from tests.browser import OfflineBrowser

WIDTH, HEIGHT = 800, 600
FOV = 75.0  # deg, vertical field of view of meshcat's default camera


@pytest.fixture
def browser(offline_browser):
    """The session's headless Chromium, its page WIDTH by HEIGHT pixels."""
    return offline_browser(WIDTH, HEIGHT)


def screenshot(page: str, browser: OfflineBrowser, folder: Path) -> np.ndarray:
    """RGB image (HEIGHT, WIDTH, 3) in [0, 1] of ``page`` rendered by headless Chromium."""
    html = folder / f"page-{hashlib.sha1(page.encode()).hexdigest()[:12]}.html"  # (one file a page: loaded afresh)
    html.write_text(page, encoding="utf-8")
    browser.load(html.as_uri())
    browser.frames()
    img = browser.screenshot()
    assert browser.errors == []
    return img


def colour_masks(img: np.ndarray, *rgbs: int) -> list[np.ndarray]:
    """For each colour of ``rgbs``: the pixels of its hue (within 7 degrees), saturated (at least 0.6 of its
    saturation, 0.5 at most) and not dark: its lit and shaded surfaces. (The image turned to HSV once: 0.25 s each.)"""
    hsv = mcolors.rgb_to_hsv(img)
    out = []
    for rgb in rgbs:
        ref = mcolors.rgb_to_hsv(np.array([(rgb >> 16) & 255, (rgb >> 8) & 255, rgb & 255]) / 255.0)
        dh = np.abs((hsv[..., 0] - ref[0] + 0.5) % 1.0 - 0.5)
        out.append((dh < 0.02) & (hsv[..., 1] > min(0.5, 0.6 * ref[1])) & (hsv[..., 2] > 0.2))
    return out


def camera(cmds: list[dict]):
    """Camera position in meshcat's world, and the shift of the mechanism's node, from the snapshot's commands."""
    pos = [c for c in cmds if c["type"] == "set_property" and c["path"] == "/Cameras/default/rotated/<object>"]
    a, b, c = pos[0]["value"]  # in the camera's parent frame, turned +90 deg about x
    root = [c for c in cmds if c["type"] == "set_transform" and c["path"] == viz.ROOT]
    shift = np.array(root[0]["matrix"]).reshape(4, 4).T[:3, 3]
    return np.array([a, -c, b]), shift


def project(points: np.ndarray, eye: np.ndarray) -> np.ndarray:
    """Pixel coordinates (column, row) of world points seen from ``eye`` looking at the origin, z up."""
    f = -eye / np.linalg.norm(eye)
    r = np.cross(f, [0.0, 0.0, 1.0])
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    rel = points - eye
    t = np.tan(np.radians(FOV) / 2)
    depth = rel @ f
    return np.c_[WIDTH / 2 + (rel @ r) / depth / t * HEIGHT / 2, HEIGHT / 2 - (rel @ u) / depth / t * HEIGHT / 2]


def test_headless_chromium_shows_the_delta_where_the_camera_looks(browser, tmp_path):
    """The Delta's snapshot renders with its motors, passive joints and platform in their colours, framed."""
    mech = pkm.load("delta")
    page = viz.snapshot_html(mech, legend=False)  # (the 3-D drawing alone; the legend: the last test)
    img = screenshot(page, browser, tmp_path)
    assert img.shape == (HEIGHT, WIDTH, 3)
    assert img.std() > 0.05  # not blank

    actuated, passive, platform = colour_masks(img, viz.ACTUATED_COLOR, viz.PASSIVE_COLOR, viz.PLATFORM_COLOR)
    assert actuated.sum() > 600 and passive.sum() > 600 and platform.sum() > 150

    # where the snapshot's camera says each joint and the platform are
    cmds = [umsgpack.unpackb(base64.b64decode(s)) for s in json.loads(
        re.search(r'id="pkm-meshcat-commands">(.*?)</script>', page, re.DOTALL).group(1))]
    eye, shift = camera(cmds)
    data = mech.model.createData()
    pin.forwardKinematics(mech.model, data, mech.q_reference)
    pin.updateFramePlacements(mech.model, data)
    motors = np.array([data.oMi[mech.model.getJointId(n)].translation for n in mech.actuated_names])
    for col, row in project(motors + shift, eye).round().astype(int):
        assert 0 <= col < WIDTH and 0 <= row < HEIGHT
        assert actuated[max(row - 4, 0):row + 5, max(col - 4, 0):col + 5].sum() >= 10
    centre = data.oMf[mech.ee_frame].translation
    (col, row), = project(centre[None] + shift, eye)
    rows, cols = np.nonzero(platform)
    assert abs(cols.mean() - col) < 15 and abs(rows.mean() - row) < 15

    # framed: the joints spread over much of the picture, inside its margins
    rows, cols = np.nonzero(actuated | passive)
    assert cols.max() - cols.min() > 0.4 * WIDTH and rows.max() - rows.min() > 0.3 * HEIGHT
    assert cols.min() > 0.05 * WIDTH and cols.max() < 0.95 * WIDTH
    assert rows.min() > 0.02 * HEIGHT and rows.max() < 0.95 * HEIGHT


def test_a_five_bar_from_its_files_shows_every_joint_link_and_the_base(browser, tmp_path):
    """The Gepetto-format five-bar (loaded from its files, not generated by pkm): every joint's centre, projected
    through the snapshot's camera, lands on its colour (actuated or passive); every link's midpoint, the base
    between the motors (a bar, off the world triad) and the closure point land on drawn pixels, not on the
    background."""
    mech = pkm.load(Path(__file__).resolve().parents[1] / "examples" / "gepetto_fivebar")
    page = viz.snapshot_html(mech, legend=False)  # (the 3-D drawing alone; the legend: the last test)
    img = screenshot(page, browser, tmp_path)
    cmds = [umsgpack.unpackb(base64.b64decode(s)) for s in json.loads(
        re.search(r'id="pkm-meshcat-commands">(.*?)</script>', page, re.DOTALL).group(1))]
    eye, shift = camera(cmds)
    model, data = mech.model, mech.model.createData()
    pin.forwardKinematics(model, data, mech.q_reference)
    pin.updateFramePlacements(model, data)
    background = np.median(np.concatenate([img[:, :20], img[:, -20:]], axis=1), axis=1)  # a gradient: per row
    drawn = np.abs(img - background[:, None]).max(axis=-1) > 0.08
    assert 0.005 < drawn.mean() < 0.5  # the mechanism, not the whole page

    def at(points: np.ndarray) -> list[tuple[int, int]]:
        out = [tuple(p) for p in project(np.atleast_2d(points) + shift, eye).round().astype(int)]
        assert all(0 <= c < WIDTH and 0 <= r < HEIGHT for c, r in out)
        return out

    masks = dict(zip((True, False), colour_masks(img, viz.ACTUATED_COLOR, viz.PASSIVE_COLOR), strict=True))
    for j in range(1, model.njoints):
        ((col, row),) = at(data.oMi[j].translation)
        mask = masks[model.names[j] in mech.actuated_names]
        assert mask[max(row - 4, 0):row + 5, max(col - 4, 0):col + 5].sum() >= 10, model.names[j]
    links = [(data.oMi[j].translation + data.oMi[c].translation) / 2 for j in range(1, model.njoints)
             for c in range(1, model.njoints) if model.parents[c] == j]
    fa, fb = mech.closure_frames[0]
    links += [(data.oMi[model.frames[f].parentJoint].translation + data.oMf[f].translation) / 2 for f in (fa, fb)]
    motors = [data.oMi[model.getJointId(n)].translation for n in mech.actuated_names]
    for col, row in at(np.array(links + [0.75 * motors[0] + 0.25 * motors[1], data.oMf[fa].translation])):
        assert drawn[max(row - 3, 0):row + 4, max(col - 3, 0):col + 4].any(), (col, row)


def test_the_hexapods_legs_show_in_their_colours_and_the_legend_in_the_corner(browser, tmp_path):
    """The hexapod, cluttered in grey before: each of its six legs shows in its own colour (hundreds of pixels each),
    and the page with its legend differs from the page without only in the lower left corner, where the legend
    shows every leg's colour."""
    mech = pkm.load("hexapod")
    bare = screenshot(viz.snapshot_html(mech, legend=False), browser, tmp_path)
    shown = screenshot(viz.snapshot_html(mech), browser, tmp_path)
    legs = [c for _, (c, *_) in viz.Scene.from_mechanism(mech).legend() if c in viz.LEG_COLORS]
    assert len(legs) == 6
    for color, mask in zip(legs, colour_masks(bare, *legs), strict=True):
        assert mask.sum() > 150, f"#{color:06x}"
    rows, cols = np.nonzero(np.abs(shown - bare).max(axis=-1) > 0.05)
    assert len(rows) > 2000 and cols.max() < 0.6 * WIDTH and rows.min() > 0.2 * HEIGHT  # the corner
    corner = shown[rows.min():, :cols.max() + 1]
    for color, mask in zip(legs, colour_masks(corner, *legs), strict=True):
        assert mask.sum() >= 40, f"#{color:06x} not in the legend"
