"""Identification of the dynamic parameters of any closed-loop mechanism (issue 30).

The actuator efforts are linear in the inertial parameters of the bodies and in the drives' parameters:
``τ_a = Y_a(q, q̇_a, q̈_a) θ`` (:mod:`pkm.core.identification.regressor`), with ``θ`` every body's ten standard
parameters (Pinocchio's order: ``m, m c_x, m c_y, m c_z, I_xx, I_xy, I_yy, I_xz, I_yz, I_zz``, the inertia about
the body's joint frame origin) and per actuator its reflected inertia, viscous and Coulomb friction and an offset.
"""
