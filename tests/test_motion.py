"""Motion files: the shipped cases, exact derivatives, malformed files refused."""

import numpy as np
import pytest

from pkm.errors import SpecError
from pkm.motion import load_motions
from tests.fd import richardson


def test_the_four_prs3_cases_are_shipped_with_the_papers_laws():
    """Case 2 is eq. (41): z = 0.81 + 0.005 (1 - cos(pi t / 3)); case 3 is eq. (45) on phi."""
    cases = load_motions("prs3_motions.toml")
    assert sorted(cases) == ["1", "2", "3", "4"]
    t, Y, _, _ = cases["2"].sample()
    assert len(t) == 501 and t[-1] == pytest.approx(5.0)
    assert np.allclose(Y[:, 0], 0.81 + 0.005 * (1 - np.cos(np.pi / 3 * t)), atol=1e-15)
    _, Y3, _, _ = cases["3"].sample()
    assert np.allclose(Y3[:, 2], np.pi / 36 * (1 - np.cos(np.pi / 3 * t)), atol=1e-15)


@pytest.mark.parametrize("case", ["1", "2", "3", "4"])
def test_velocities_and_accelerations_are_the_derivatives_of_the_positions(case):
    m = load_motions("prs3_motions.toml")[case]
    t = np.array([0.3, 1.7, 4.2])
    _, _, Yd, Ydd = m.sample(t)
    dY = richardson(lambda h: (m.sample(t + h)[1] - m.sample(t - h)[1]) / (2 * h), 1e-3)
    dYd = richardson(lambda h: (m.sample(t + h)[2] - m.sample(t - h)[2]) / (2 * h), 1e-3)
    assert np.allclose(dY, Yd, atol=1e-10) and np.allclose(dYd, Ydd, atol=1e-10)


@pytest.mark.parametrize("text", [
    "",
    'format = "other/1"',
    'format = "pkm.motion/1"\ncoordinates = ["z"]',
    'format = "pkm.motion/1"\ncoordinates = ["z"]\n[case.a]\nduration = 1.0\ndt = 0.1\nz = { law = "spline" }',
    'format = "pkm.motion/1"\ncoordinates = ["z"]\n[case.a]\nduration = 1.0\ndt = 2.0\nz = { law = "constant", value = 0 }',
    'format = "pkm.motion/1"\ncoordinates = ["z"]\n[case.a]\nduration = 1.0\ndt = 0.1\n'
    'z = { law = "linear", start = 0, rate = nan }',
    'format = "pkm.motion/1"\ncoordinates = ["z"]\n[case.a]\nduration = 1.0\ndt = 0.1\n'
    'z = { law = "constant", value = 0, extra = 1 }',
    "not = [toml",
    'format = "pkm.motion/1"\ncoordinates = ["z"]\n[case.a]\nduration = 1.0\ndt = 0.1\n'
    'z = { law = "hermite", t = [0.0, 1.0], position = [0.0], velocity = [0.0, 0.0] }',
    'format = "pkm.motion/1"\ncoordinates = ["z"]\n[case.a]\nduration = 1.0\ndt = 0.1\n'
    'z = { law = "hermite", t = [0.0, 0.0], position = [0.0, 1.0], velocity = [0.0, 0.0] }',
])
def test_malformed_motion_files_are_refused(tmp_path, text):
    path = tmp_path / "m.toml"
    path.write_text(text)
    with pytest.raises(SpecError):
        load_motions(path)


@pytest.mark.parametrize(("dt", "times"), [(0.25, [0.0, 0.25, 0.5, 0.75, 1.0]), (0.6, [0.0, 0.6, 1.0]),
                                            (0.4, [0.0, 0.4, 0.8, 1.0]), (0.1, [round(0.1 * k, 12) for k in range(11)])])
def test_the_samples_span_the_case_whatever_its_step(dt, times):
    """``round(duration / dt)`` steps ran past the case (dt = 0.6 over 1 s: a sample at 1.2 s) or stopped short of
    it (dt = 0.4: the last at 0.8 s); the samples now end at the duration, with a shorter last step where dt does not
    divide it."""
    import dataclasses

    case = dataclasses.replace(load_motions("prs3_motions.toml")["2"], duration=1.0, dt=dt)
    assert np.allclose(case.times(), times, rtol=0, atol=1e-12)
