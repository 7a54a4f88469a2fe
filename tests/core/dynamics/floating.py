"""The floating robots of the dynamics tests: shipped closed-loop robots hung on a free-flyer root (a pelvis over
a ``ground`` link), each with its fixed twin, built once."""

from __future__ import annotations

import dataclasses
import re
import warnings
from pathlib import Path

import pkm
from pkm.core.formats.load import load_texts

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
_CACHE: dict[str, pkm.Mechanism] = {}


def hung(fixed: pkm.Mechanism) -> pkm.Mechanism:
    """``fixed`` with its root link carried by a free-flyer ``pelvis`` on a new ``ground`` link (its floating
    base); the reference is the neutral configuration (close it)."""
    urdf = fixed.urdf
    links = re.findall(r'<link\s+name="([^"]+)"', urdf)
    children = set(re.findall(r'<child\s+link="([^"]+)"', urdf))
    root = next(link for link in links if link not in children)
    head = re.search(r"<robot[^>]*>", urdf)
    assert head is not None
    urdf = (urdf[:head.end()] + f'\n  <link name="ground"/>\n  <joint name="pelvis" type="floating">\n    <parent '
            f'link="ground"/>\n    <child link="{root}"/>\n  </joint>' + urdf[head.end():])
    return pkm.from_strings(urdf, dataclasses.replace(fixed.spec, floating_base="pelvis", reference={}))


def floating(name: str) -> pkm.Mechanism:
    """``"ankle"`` (the acceptance set's ankle: idle rods between balls), ``"delta"`` (the shipped Delta) or
    ``"fourbar"`` (the MJCF four-bar under a free 2-kg pelvis body: a planar loop closed by a 3-D point)."""
    if name not in _CACHE:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if name == "ankle":
                _CACHE[name] = hung(pkm.load(EXAMPLES / "ankle" / "ankle.closures.toml"))
            elif name == "delta":
                _CACHE[name] = hung(pkm.load("delta"))
            else:
                text = (EXAMPLES / "mjcf_fourbar" / "fourbar.xml").read_text()
                text = text.replace("<worldbody>", '<worldbody>\n    <body name="pelvis" pos="0 0 1"><freejoint '
                                    'name="root"/><geom type="sphere" size="0.05" mass="2"/>').replace(
                    "</worldbody>", "</body></worldbody>")
                _CACHE[name] = load_texts({"floating.xml": text})
    return _CACHE[name]


FLOATING = ("ankle", "delta", "fourbar")
