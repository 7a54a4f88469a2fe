"""The motors of a mechanism whose ``[motors]`` drive several actuated joints through a constant linear map (a
differential; :mod:`pkm.core.model.motors`): their coordinates and efforts from the actuated joints' and back.

``C`` is :attr:`Mechanism.motor_map.matrix <pkm.core.model.motors.MotorMap>` (``na x na``): the motors' coordinates
are ``C q_a``, their velocities ``C dq_a``, and by virtual work their efforts ``f`` act on the actuated joints as
``tau_a = C^T f``. pkm's dynamics (:func:`pkm.inverse_dynamics`, :func:`pkm.forward_dynamics`, :func:`pkm.simulate`)
speak actuated-joint efforts; these convert. Without ``[motors]``, ``C`` is the identity.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from pkm.core.model.mechanism import Mechanism, check_mechanism
from pkm.validation import as_vector


def motor_values(mech: Mechanism, q: ArrayLike) -> np.ndarray:
    """The motors' coordinates ``C q_a`` (na) at the configuration ``q`` (module doc; each up to the constant the
    model file may add: MuJoCo's tendon length has none).

    Examples:
        >>> import dataclasses
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")  # motor_1 and motor_2 driven by a differential instead, for the example
        >>> spec = dataclasses.replace(delta.spec, motors={"sum": {"motor_1": 1.0, "motor_2": 1.0},
        ...                                                "diff": {"motor_1": 1.0, "motor_2": -1.0}})
        >>> geared = pkm.from_strings(delta.urdf, spec)
        >>> geared.motor_map.names
        ('sum', 'diff', 'motor_3')
        >>> q = geared.with_actuated(geared.q_reference, [0.3, 0.1, 0.2])
        >>> np.round(pkm.motor_values(geared, q), 3)
        array([0.4, 0.2, 0.2])
    """
    m = check_mechanism(mech)
    return m.motor_map.matrix @ m.actuated_q(m.check_q(q))


def motor_efforts(mech: Mechanism, tau_actuated: ArrayLike) -> np.ndarray:
    """The motors' efforts ``f = C^-T tau_a`` (na, in motor order: :attr:`MotorMap.names <pkm.core.model.motors.MotorMap>`) that apply the actuated
    joints' efforts ``tau_a`` (na, in ``actuated`` order; :func:`pkm.inverse_dynamics` gives them).

    Examples:
        >>> import dataclasses
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")  # motor_1 and motor_2 driven by a differential instead, for the example
        >>> spec = dataclasses.replace(delta.spec, motors={"sum": {"motor_1": 1.0, "motor_2": 1.0},
        ...                                                "diff": {"motor_1": 1.0, "motor_2": -1.0}})
        >>> geared = pkm.from_strings(delta.urdf, spec)
        >>> np.round(pkm.motor_efforts(geared, [1.0, 0.0, 2.0]), 3)  # half of motor_1's effort from each
        array([0.5, 0.5, 2. ])
    """
    m = check_mechanism(mech)
    return np.linalg.solve(m.motor_map.matrix.T, as_vector(tau_actuated, m.na, "tau_actuated"))


def joint_efforts(mech: Mechanism, motor_effort: ArrayLike) -> np.ndarray:
    """The actuated joints' efforts ``tau_a = C^T f`` (na, ``actuated`` order) of the motors' efforts ``f`` (na, in
    motor order): what :func:`pkm.forward_dynamics` and :func:`pkm.simulate` take.

    Examples:
        >>> import dataclasses
        >>> import numpy as np
        >>> import pkm
        >>> delta = pkm.load("delta")  # motor_1 and motor_2 driven by a differential instead, for the example
        >>> spec = dataclasses.replace(delta.spec, motors={"sum": {"motor_1": 1.0, "motor_2": 1.0},
        ...                                                "diff": {"motor_1": 1.0, "motor_2": -1.0}})
        >>> geared = pkm.from_strings(delta.urdf, spec)
        >>> np.round(pkm.joint_efforts(geared, [1.0, 0.0, 2.0]), 3)  # the "sum" motor turns both joints
        array([1., 1., 2.])
    """
    m = check_mechanism(mech)
    return m.motor_map.matrix.T @ as_vector(motor_effort, m.na, "motor_effort")


__all__ = ["joint_efforts", "motor_efforts", "motor_values"]
