"""pkm.core.modes.modeset: a set's account in words."""

from __future__ import annotations

from pkm.core.modes.modeset import ModeSet


def _set(n_complex: int, n_exceptional: int, n_infinite: int, failed: tuple = ()) -> ModeSet:
    return ModeSet(modes=(), complete=not failed, method="a total-degree homotopy", n_paths=40, bound=40,
                   n_complex=n_complex, n_infinite=n_infinite, n_exceptional=n_exceptional, failed=failed,
                   reduction="", seconds=0.0)


def test_the_summary_says_the_other_solutions_are_no_assembly_mode():
    """``pkm fk --all``'s "25 complex, 3 exceptional" read as an error: the sentence now says these are the
    polynomial system's solutions that are not real assembly modes, each count as the fields hold it."""
    text = _set(25, 3, 12).summary()
    assert text.startswith("0 real assembly mode(s); the polynomial system's other solutions, which are no assembly "
                           "mode: 25 complex, 3 exceptional (real, not a pose")
    assert "12 at infinity; from 40 paths of a total-degree homotopy; complete" in text
    assert _set(0, 0, 0, failed=(object(),)).summary().endswith("NOT complete: 1 path(s) failed")
