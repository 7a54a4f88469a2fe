"""The robots the transmission tests share, each loaded and decomposed once per test process."""

from __future__ import annotations

import warnings
from pathlib import Path

import pkm
from tests.test_gepetto_robots import gepetto

EXAMPLES = Path(__file__).resolve().parents[3] / "examples"
#: name -> how to load it: the shipped humanoid ankle (MJCF) and knee (URDF), the SDF slider-crank, the acceptance
#: set's ankle and knee (URDF + spec), and Gepetto's bipeds (URDF + YAML; battobot: two legs, six loops; Cassie's and
#: Digit's ankles, their knee loops left out).
FILES = {
    "humanoid_ankle": EXAMPLES / "humanoid_ankle" / "ankle.closures.toml",
    "humanoid_knee": EXAMPLES / "humanoid_knee" / "knee.closures.toml",
    "slider_crank": EXAMPLES / "sdf_slider_crank" / "slider_crank.closures.toml",
    "ankle": EXAMPLES / "ankle" / "ankle.closures.toml",
    "knee": EXAMPLES / "knee" / "knee.closures.toml",
}
GEPETTO = ("battobot_6d", "talos_like", "cassie_like", "digit_like")
#: The robots one of whose loops is no transmission (its chain outnumbers its motors): decomposed with skip_unfit.
UNFIT = ("cassie_like", "digit_like")
_MECHS: dict[str, pkm.Mechanism] = {}
_TRANSMISSIONS: dict[str, list[pkm.Transmission]] = {}


def robot(name: str) -> pkm.Mechanism:
    """The robot ``name`` (a key of :data:`FILES` or one of :data:`GEPETTO`)."""
    if name in GEPETTO:
        return gepetto(name)
    if name not in _MECHS:
        _MECHS[name] = pkm.load(FILES[name])
    return _MECHS[name]


def transmissions(name: str) -> list[pkm.Transmission]:
    """``pkm.transmissions`` of the robot ``name``, once."""
    if name not in _TRANSMISSIONS:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", pkm.errors.PkmWarning)  # (the loop left out: its own test checks it)
            _TRANSMISSIONS[name] = pkm.transmissions(robot(name), skip_unfit=name in UNFIT)
    return _TRANSMISSIONS[name]


ROBOTS = (*FILES, *GEPETTO)
