"""Shared, expensive pieces of the calibration tests: one model, one pose set and one simulated calibration per
mechanism, built once a run."""

from __future__ import annotations

import functools
import warnings
from dataclasses import dataclass

import numpy as np

import pkm
from pkm.core.calibration.estimate import Calibration, calibrate, perturbed, simulate
from pkm.core.calibration.measurement import CalibrationModel
from pkm.core.calibration.poses import calibration_poses, candidates

#: mechanism -> (measurement model, poses, reading spread [rad or m])
SETUPS = {"prs3": ("pose", 16, 0.2), "gepetto:5bar_linkage": ("passive", 16, 0.3)}
NOISE = {"m": 10e-6, "rad": 20e-6}


@functools.cache
def mechanism(name: str) -> pkm.Mechanism:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pkm.errors.PkmWarning)  # (the Gepetto five-bar's implausible masses)
        return pkm.load(name)


@functools.cache
def model(name: str, kind: str | None = None) -> CalibrationModel:
    return CalibrationModel(mechanism(name), kind or SETUPS[name][0])


@dataclass(frozen=True)
class Simulated:
    """A simulated calibration: the truth, the poses, the noisy and the held-out measurements, the result."""

    model: CalibrationModel
    truth: np.ndarray
    readings: np.ndarray
    measured: np.ndarray
    held_out: np.ndarray
    held_truth: np.ndarray
    cal: Calibration


@functools.cache
def simulated(name: str) -> Simulated:
    """Every parameter perturbed (lengths 2 mm, angles 0.5 degree, gains 1e-3), measured with a laser tracker's
    noise at O1-chosen poses, calibrated; 10 held-out poses measured without noise."""
    _, n, spread = SETUPS[name]
    m = model(name)
    readings = calibration_poses(m, n, spread=spread, pool=3 * n).readings
    truth = perturbed(m, seed=3)
    measured = simulate(m, truth, readings, sigma=NOISE, seed=4)
    held = candidates(m, 10, spread=spread, seed=11)
    return Simulated(m, truth, readings, measured, held, simulate(m, truth, held, sigma={"m": 0.0, "rad": 0.0}),
                     calibrate(m, readings, measured, sigma=NOISE))
