"""Third-party robot files that pkm ships, loaded by name: ``pkm.load("gepetto:robot_delta")``.

Gepetto's example-parallel-robots (LAAS-CNRS, INRIA; BSD-3-Clause: ``urdf/gepetto/LICENSE``, the commit in
``urdf/gepetto/SOURCE.txt``) are ten robots exported from Onshape, a URDF and a ``robot.yaml`` each in the
convention of the toolbox-parallel-robots (:func:`pkm.core.formats.load.load_gepetto`), shipped unmodified in
``urdf/gepetto/<robot>/`` (``pkm/_data/urdf/gepetto/`` in a wheel). They are what pkm's tests and benchmarks meet
as a user's own files would be: nothing in them was written for pkm. A name is ``gepetto:<robot>``, a key of
:data:`CATALOGUE`; ``pkm list`` lists them.

``gepetto:kangaroo_like`` is shipped as a robot pkm must refuse: its 6-D loops do not close at any pose the file
allows, and :func:`pkm.load` says which closure.

MuJoCo Menagerie's robots (Google DeepMind's collection; each robot under its own licence, beside it) are MJCF files
as published but for their meshes (mesh geoms and assets removed: kinematics and dynamics need none, every inertia is
stated), in ``urdf/menagerie/<folder>/`` with the robot's ``LICENSE`` and a ``SOURCE.txt`` naming the repository, the
path, the commit and every change. ``menagerie:cassie`` is Agility Robotics' Cassie (MIT): a real humanoid's legs,
two loops each (the achilles rod from the hip to the heel spring, the plantar rod from the foot crank to the foot),
a free-floating pelvis, ten motors, its reference the file's ``home`` key with its loops closed.
``menagerie:robotiq_2f85`` is Robotiq's 2F-85 gripper (BSD-2-Clause): two adaptive four-bar fingers (a spring on
each, one passive freedom each), one motor on a tendon over the two drivers, which a joint equality ties.
``menagerie:xarm7`` is UFACTORY's xArm7 (BSD-3-Clause): a seven-joint arm carrying a gripper whose two fingers are
parallelograms closed by connects (no passive freedom), one motor on a tendon over the two drivers, a joint equality
tying them; its reference the file's ``home`` key.

Robots published in their makers' own repositories are shipped the same way, in ``urdf/<project>/<robot>/`` with
their ``LICENSE`` and ``SOURCE.txt``: ``toddlerbot:toddlerbot`` is Stanford's ToddlerBot (``hshi74/toddlerbot``,
MIT): a 30-motor humanoid whose knees and neck pitch are rod linkages closed by six welds, nine gear pairs read as
mimic couplings, a waist whose two limited fixed tendons no motor drives (noted, not read), a free torso.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from pkm.errors import SpecError, UnknownNameError


@dataclass(frozen=True)
class CatalogueModel:
    """A robot pkm ships from a third party, with where it came from.

    Attributes:
        folder: Its folder, relative to pkm's ``urdf/`` data folder.
        source: The project and licence it comes under (the licence file beside it).
        description: One line: what the robot is.
        model: The file in ``folder`` that :func:`pkm.load` reads (an MJCF file alone), or ``""``: the folder itself
            (a Gepetto URDF + YAML pair).
    """

    folder: str
    source: str
    description: str
    model: str = ""


_GEPETTO = "Gepetto/example-parallel-robots, BSD-3-Clause (urdf/gepetto/LICENSE)"


def _gepetto(robot: str, description: str) -> tuple[str, CatalogueModel]:
    return f"gepetto:{robot}", CatalogueModel(f"gepetto/{robot}", _GEPETTO, description)


def _published(project: str, repository: str, robot: str, folder: str, model: str, licence: str,
               description: str) -> tuple[str, CatalogueModel]:
    source = f"{repository}, {licence} (urdf/{project}/{folder}/LICENSE)"
    return f"{project}:{robot}", CatalogueModel(f"{project}/{folder}", source, description, model)


def _menagerie(robot: str, folder: str, model: str, licence: str, description: str) -> tuple[str, CatalogueModel]:
    return _published("menagerie", "google-deepmind/mujoco_menagerie", robot, folder, model, licence, description)


#: Every shipped third-party robot by name ``<source>:<robot>``, sorted.
CATALOGUE: dict[str, CatalogueModel] = dict([
    _gepetto("5bar_linkage", "a planar five-bar, one 6-D loop, two motors"),
    _gepetto("5bar_linkage_iso3d", "a five-bar closed by a 3-D point, two motors"),
    _gepetto("battobot_6d", "a biped: parallel knees and ankles, six 6-D loops, twelve motors"),
    _gepetto("cassie_like", "a Cassie-like leg: two 6-D loops, five motors"),
    _gepetto("digit_like", "a Digit-like leg: three 6-D loops, six motors"),
    _gepetto("disney_like", "a Disney-like leg: three four-bars, six motors"),
    _gepetto("kangaroo_like", "a Kangaroo-like leg whose 6-D loops do not close (refused on load)"),
    _gepetto("robot_delta", "a small Delta-like arm (links of about 5 cm): three 6-D loops, two motors"),
    _gepetto("talos_like", "a TALOS-like leg: one 6-D loop, six motors"),
    _gepetto("wl16_like", "a WL-16-like leg: five 6-D loops, six motors"),
    _menagerie("cassie", "agility_cassie", "cassie.xml", "MIT",
               "Agility Robotics' Cassie biped (MJCF, meshes removed): four 3-D loops, ten motors, a free pelvis"),
    _menagerie("robotiq_2f85", "robotiq_2f85", "2f85.xml", "BSD-2-Clause",
               "Robotiq's 2F-85 adaptive gripper (MJCF, meshes removed): two four-bar fingers closed by connects, "
               "one motor on a tendon over the two drivers, a gear equality tying them"),
    _menagerie("xarm7", "ufactory_xarm7", "xarm7.xml", "BSD-3-Clause",
               "UFACTORY's xArm7 arm with its gripper (MJCF, meshes removed): seven motors, two parallelogram "
               "fingers closed by connects, one motor on a tendon over the two drivers, a gear equality tying them"),
    _published("toddlerbot", "hshi74/toddlerbot", "toddlerbot", "toddlerbot", "toddlerbot.xml", "MIT",
               "Stanford's ToddlerBot humanoid (MJCF, meshes removed): rod-driven knees and neck closed by six "
               "welds, nine gear couplings, 30 motors, a free torso"),
])


def catalogue_path(name: str) -> Path:
    """What :func:`pkm.load` reads of shipped robot ``name`` (``<source>:<robot>``): its folder, or its model file
    (:attr:`CatalogueModel.model`).

    Raises:
        UnknownNameError: no such robot (the valid names listed).
        SpecError: its folder or file is missing from this installation.
    """
    from pkm.data import data_dir

    if name not in CATALOGUE:
        raise UnknownNameError("shipped robot", name, CATALOGUE, "pkm's catalogue of third-party robots")
    entry = CATALOGUE[name]
    folder = data_dir("urdf") / entry.folder
    path = folder / entry.model if entry.model else folder
    if not (path.is_file() if entry.model else path.is_dir()):
        raise SpecError(name, f"the shipped robot's {'file' if entry.model else 'folder'} {path} is missing from "
                              "this installation")
    return path


__all__ = ["CATALOGUE", "CatalogueModel", "catalogue_path"]
