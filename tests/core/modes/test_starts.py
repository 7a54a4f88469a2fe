"""Generic start systems (:mod:`pkm.core.modes.starts`): the shipped ones are read from their files byte for byte,
an unshipped family is solved once per process with the literature's root counts, and the parameter path runs from
the target to the generic parameters. (The shipped starts' residuals: ``test_equations.py``.)"""

from __future__ import annotations

import numpy as np
import pytest

from pkm.core.modes import starts
from pkm.core.modes.equations import N_UNKNOWNS, equations
from pkm.core.modes.polynomial import System, variables

pytest.importorskip("bertini")


@pytest.mark.parametrize("path", sorted(starts._DIR.glob("*.json")), ids=lambda p: p.stem)
def test_a_shipped_start_round_trips_through_its_json(path):
    """from_json then to_json gives the file back (its text, bar the final newline), so every complex number is kept
    exactly; the parameters have the sizes of their leg kinds."""
    text = path.read_text()
    start = starts.GenericStart.from_json(text)
    assert start.to_json() == text.rstrip("\n") and start.signature == path.stem.replace("-", ":")
    group, kinds = start.signature.split(":")
    assert [p.size for p in start.params] == [starts._N_PARAMS[group, k] for k in kinds]
    again = starts.GenericStart.from_json(start.to_json())
    assert all(np.array_equal(a, b) for a, b in zip(again.points + again.params, start.points + start.params))


def test_shipped_families_are_read_and_others_computed_once(monkeypatch):
    """generic_start reads a shipped family without solving anything (compute replaced by a failing stub) and
    solves another family once per process (the second call returns the same object)."""
    calls = []
    real = starts.compute

    def counting(signature, *args, **kwargs):
        calls.append(signature)
        if signature.startswith("SE3"):
            raise AssertionError("a shipped family was computed")
        return real(signature, *args, **kwargs)

    monkeypatch.setattr(starts, "compute", counting)
    starts.generic_start.cache_clear()
    try:
        assert len(starts.generic_start("SE3:ssssss").points) == 40
        first = starts.generic_start("T3:sss")
        assert starts.generic_start("T3:sss") is first and calls == ["T3:sss"]
    finally:
        starts.generic_start.cache_clear()  # (nothing computed under the stub stays cached)


@pytest.mark.parametrize("signature, count", [("SE2:sss", 6), ("T3:sss", 2)])
def test_a_computed_start_has_the_known_number_of_generic_solutions(signature, count):
    """At random complex parameters every path ends (none failed) and the isolated solutions number the literature's:
    6 for the planar three-sphere (3-RRR/3-RPR) family (Gosselin & Sefrioui 1991), 2 for three spheres in
    translation (the Delta); each solves its system (1e-10 relative)."""
    start = starts.compute(signature, seed=3, threads=1)
    assert start.complete and len(start.points) == count and start.seed == 3
    group, _ = signature.split(":")
    S = System(equations(group, start.params, variables(N_UNKNOWNS[group])))
    for x in start.points:
        assert np.abs(S(x)).max() <= 1e-10 * max(1.0, np.abs(x).max()) ** 2


def test_the_parameter_path_runs_from_the_target_to_the_generic_parameters():
    """path_parameters at t = 0 is the target's parameters, at t = 1 the start's, and linear between (1e-15)."""
    start = starts.generic_start("SE3:ccc")
    rng = np.random.default_rng(4)
    target = [rng.normal(size=p.size) for p in start.params]
    (t,) = variables(1)
    path = starts.path_parameters(target, start, t)
    for s in (0.0, 0.3, 1.0):
        for P, G, row in zip(target, start.params, path):
            value = np.array([p(np.array([s])) for p in row])
            assert np.abs(value - ((1 - s) * P + s * G)).max() <= 1e-15 * 4
