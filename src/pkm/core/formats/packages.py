"""Models that an installed package ships, loaded by name: ``pkm.load("example-robot-data:cassie")``.

A name is ``<package>:<model>``, a key of :data:`PACKAGE_MODELS`. The package is a Python distribution whose
model files pkm reads where it installed them (:data:`PACKAGES`: the folder inside the distribution, found with
:func:`importlib.metadata.distribution`; nothing is copied into pkm, whose licence does not cover them). A model
file that names no actuators (SDFormat) comes with a small closure spec that pkm ships,
``urdf/<package>/<model>.closures.toml`` (``pkm/_data/urdf/...`` in a wheel): its ``actuated`` joints and
``[joint_types]``; the loops are the file's own. Its ``urdf`` key is the model file's path relative to the
package's model folder (not to the spec).

Cassie (example-robot-data, ``cassie_description/robots/``): ``cassie`` (``cassie.sdf``: each motor an output
joint ``*-op`` geared to its rotor ``*-ip`` by an SDFormat gearbox, read as a mimic joint: see
:mod:`pkm.core.formats.sdf`) and ``cassie_v2`` (``cassie_v2.sdf``: no rotors). The ten motors are each leg's hip
roll, yaw and pitch, knee and foot (``*-op``). Each leg has two leaf springs, revolutes with a stiffness
(``knee-shin-joint``, ``tarsus-spring-joint``), and two loops: the achilles rod (a ball at the hip, a revolute at
the heel spring, tilted 4.5 degrees out of the leg's plane) and the plantar rod of the foot. Held rigid both, the
springs make the achilles loop an RRR-S loop that cannot move, so the knee motor is locked (mobility 8 for ten
motors); both free, they add motions that no motor drives (two for ``cassie_v2``; ``cassie``'s knee-spring loop
is all but redundant, its smallest nonzero singular values 1e-5 and 7e-7). pkm's specs hold the knee spring
rigid and leave the heel spring free: mobility 10, well conditioned, but the heel spring then takes up the
achilles loop as the knee turns (about -2 rad per rad near the file's pose), as the files' geometry forces.
Which stiffnesses set the deflections is statics, outside a kinematic model. ``cassie_v2.sdf`` rounds its right
foot's poses (roll 1.5708, pitches 1.3439 and 1.364), so its toe motor's axis is 7.4e-8 rad off the foot crank's:
that plantar loop moves only by opening about 1e-9 m, 2.3e-9 of its characteristic length
(``pkm.close_loops(..., tol=5e-9)``); the other loops close
to round-off.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from pkm.errors import SpecError, UnknownNameError

if TYPE_CHECKING:
    pass

#: The packages pkm reads models from: distribution name -> its model folder, relative to the distribution's
#: install location (:meth:`importlib.metadata.Distribution.locate_file`).
PACKAGES: dict[str, str] = {"example-robot-data": "cmeel.prefix/share/example-robot-data/robots"}


@dataclass(frozen=True)
class PackageModel:
    """A model an installed package ships, with the closure spec pkm ships for it.

    Attributes:
        package: The distribution that installs the model file (a key of :data:`PACKAGES`).
        spec: The closure spec, relative to pkm's ``urdf/`` data folder; its ``urdf`` key is the model file,
            relative to the package's model folder.
        description: One line: what the model is.
    """

    package: str
    spec: str
    description: str


#: Every model by name ``<package>:<model>``, sorted.
PACKAGE_MODELS: dict[str, PackageModel] = {
    "example-robot-data:cassie": PackageModel(
        "example-robot-data", "example-robot-data/cassie.closures.toml",
        "Agility Robotics' Cassie biped (cassie.sdf): ten geared motors, rotors as mimic joints"),
    "example-robot-data:cassie_v2": PackageModel(
        "example-robot-data", "example-robot-data/cassie_v2.closures.toml",
        "Agility Robotics' Cassie biped (cassie_v2.sdf): ten motors, no rotors"),
}


def package_dir(package: str) -> Path:
    """The folder where the installed ``package`` keeps its models.

    Raises:
        UnknownNameError: ``package`` is not one pkm reads models from (:data:`PACKAGES`).
        SpecError: it is not installed, or its model folder is missing.
    """
    from importlib import metadata

    if package not in PACKAGES:
        raise UnknownNameError("package", package, PACKAGES, "pkm's packages of models")
    try:
        folder = Path(str(metadata.distribution(package).locate_file(PACKAGES[package])))
    except metadata.PackageNotFoundError:
        raise SpecError(package, f"the package is not installed: pip install {package}") from None
    if not folder.is_dir():
        raise SpecError(package, f"the installed package has no model folder {folder}")
    return folder


def model_file(name: str) -> tuple[Path, Path]:
    """The closure spec pkm ships for model ``name`` (``<package>:<model>``) and the package's model file it names.

    Raises:
        UnknownNameError: no such model (the valid names listed).
        SpecError: the package is not installed, the file is missing, or the spec's path leaves the package.
    """
    from pkm.core.model.spec import ClosureSpec
    from pkm.data import data_dir

    if name not in PACKAGE_MODELS:
        raise UnknownNameError("package model", name, PACKAGE_MODELS, "pkm's models of installed packages")
    entry = PACKAGE_MODELS[name]
    spec_path = data_dir("urdf") / entry.spec
    spec = ClosureSpec.load(spec_path)
    folder = package_dir(entry.package).resolve()
    path = (folder / spec.urdf).resolve()
    if not path.is_relative_to(folder) or not path.is_file():
        raise SpecError(name, f"{entry.package} has no model file {spec.urdf!r} in {folder}")
    return spec_path, path


__all__ = ["PACKAGES", "PACKAGE_MODELS", "PackageModel", "model_file", "package_dir"]
