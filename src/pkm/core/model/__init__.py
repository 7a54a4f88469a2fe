"""The model of a mechanism: the Pinocchio tree, its closure spec, URDF reading and writing, joints URDF
cannot state, the comparison of two models."""
