"""Every public function's docs page teaches by an example that runs: each function of ``pkm.__all__`` (and the
classes users construct or receive most: :class:`pkm.Mechanism`, :class:`pkm.Kernels`, :class:`pkm.Simulation`;
the package's own quick start)
has a Google ``Examples:`` section in its docstring whose ``>>>`` lines pass under :mod:`doctest` (ELLIPSIS,
NORMALIZE_WHITESPACE; fresh globals: each example imports what it uses, as a reader copying it would), and each
function is fully annotated (what its page's signature shows). One item per name, so that pytest-xdist spreads
them; all of them together take about 15 s (the shipped mechanisms are loaded once per process by ``pkm.load``).
"""

from __future__ import annotations

import doctest
import inspect
import re

import pytest

import pkm

FUNCTIONS = sorted(n for n in pkm.__all__ if inspect.isfunction(getattr(pkm, n)))
CLASSES = ["Kernels", "Mechanism", "Simulation"]
PACKAGE = ["pkm"]  # the package page's quick start
FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE


def test_the_public_functions_are_all_found() -> None:
    """The 66 functions of ``pkm.__all__`` (a lazy name not resolving to a function would drop out silently)."""
    assert len(FUNCTIONS) >= 66 and {"load", "solve_ik", "inverse_dynamics", "sweep", "zyx_matrix"} <= set(FUNCTIONS)


def _examples(name: str) -> list[doctest.Example]:
    doc = inspect.getdoc(pkm if name == "pkm" else getattr(pkm, name)) or ""
    assert re.search(r"^Examples:\n", doc, re.MULTILINE), f"pkm.{name}'s docstring has no 'Examples:' section"
    section = doc.split("\nExamples:\n", 1)[1]
    examples = doctest.DocTestParser().get_examples(section)
    assert examples, f"pkm.{name}'s 'Examples:' section has no >>> lines"
    return examples


@pytest.mark.parametrize("name", FUNCTIONS + CLASSES + PACKAGE)
def test_the_example_runs(name: str) -> None:
    """The section's examples give the output they show; a failing example fails naming the function."""
    test = doctest.DocTest(_examples(name), {}, f"pkm.{name}", None, None, None)
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    out: list[str] = []
    runner.run(test, out=out.append)
    assert runner.failures == 0, f"pkm.{name}'s example failed:\n" + "".join(out)


def test_a_wrong_output_fails() -> None:
    """The runner above compares the outputs (a doctest that printed nothing would pass any example)."""
    wrong = doctest.DocTestParser().get_examples(">>> 1 + 1\n3\n")
    runner = doctest.DocTestRunner(optionflags=FLAGS)
    runner.run(doctest.DocTest(wrong, {}, "wrong", None, None, None), out=lambda _: None)
    assert runner.failures == 1


@pytest.mark.parametrize("name", FUNCTIONS)
def test_the_signature_is_fully_annotated(name: str) -> None:
    """Every parameter (``*args`` and ``**kwargs`` too) and the return carry an annotation."""
    sig = inspect.signature(getattr(pkm, name))
    missing = [p.name for p in sig.parameters.values() if p.annotation is inspect.Parameter.empty]
    if sig.return_annotation is inspect.Signature.empty:
        missing.append("return")
    assert not missing, f"pkm.{name}: no annotation on {', '.join(missing)}"
