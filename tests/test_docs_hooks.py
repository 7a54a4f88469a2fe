"""The docs site's hook (``docs/hooks.py``) typesets every formula as MathML when the site is built: the docstrings'
``:math:`` roles and pymdownx.arithmatex's ``$..$`` / ``$$..$$`` (no MathJax, no CDN: the site's maths shows
offline); what latex2mathml cannot render is a warning (a ``--strict`` build fails), never raw TeX shipped silently.
Needs the ``docs`` extra (latex2mathml, Markdown with pymdownx); ``tools/offline_site.py`` checks the built site in
Chromium in CI."""

from __future__ import annotations

import importlib.util
import logging
import re
from pathlib import Path

import pytest

pytest.importorskip("latex2mathml", reason="the docs extra (pip install -e .[docs])")
markdown = pytest.importorskip("markdown", reason="the docs extra (pip install -e .[docs])")

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def hooks():
    spec = importlib.util.spec_from_file_location("pkm_docs_hooks", ROOT / "docs" / "hooks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def page(text: str) -> str:
    """The HTML of Markdown ``text`` as the site's configuration makes it (arithmatex, generic output)."""
    md = markdown.Markdown(extensions=["pymdownx.arithmatex"],
                           extension_configs={"pymdownx.arithmatex": {"generic": True}})
    return md.convert(text)


def test_inline_and_display_maths_become_mathml(hooks, caplog):
    """``$..$``, ``\\(..\\)``, ``$$..$$`` and ``\\[..\\]``: MathML, inline or a block, with the formula's structure
    (a fraction, a dotted q, an exponent), and no TeX delimiter left."""
    html = page("The model $\\tau = M_a(q)\\,\\ddot q + h_a(q, \\dot q)$ and \\(a < b\\).\n\n"
                "$$\n\\frac{\\partial f}{\\partial q}\n$$\n\n\\[ x^2 \\]\n")
    assert html.count('class="arithmatex"') == 4  # (what the hook receives)
    with caplog.at_level(logging.WARNING):
        out = hooks.render_maths(html, "page.md")
    assert caplog.records == []
    assert "\\(" not in out and "\\[" not in out and "$" not in out
    assert len(re.findall(r'<math [^>]*display="inline"', out)) == 2
    assert len(re.findall(r'<div class="arithmatex"[^>]*><math [^>]*display="block"', out)) == 2
    assert "<mfrac>" in out and "<msup><mi>x</mi><mn>2</mn></msup>" in out
    assert "<mover><mi>q</mi><mo>&#x000A8;</mo></mover>" in out  # (q double dot)
    assert "<mo>&#x0003C;</mo>" in out  # (a < b: the operator, not the escaped text &lt;)


def test_a_math_role_becomes_inline_mathml_and_other_roles_stay_references(hooks):
    html = "<p>where :math:<code>|r| \\le 1</code>, see :func:<code>pkm.load</code>.</p>"
    out = hooks.render_roles(html, None, "page.md")
    assert ":math:" not in out and '<math xmlns="http://www.w3.org/1998/Math/MathML" display="inline">' in out
    assert "<mo>&#x02264;</mo>" in out  # (\le)
    assert '<autoref identifier="pkm.load" optional><code>pkm.load</code></autoref>' in out


@pytest.mark.parametrize("tex", ["\\arg\\min_x f", "\\begin{aligned} a &= b \\end{aligned}", "x^"])
def test_tex_latex2mathml_leaves_as_text_is_a_warning(hooks, caplog, tex):
    """A command latex2mathml does not know (it would print ``\\arg``), an ``&`` it does not align, TeX it refuses
    (an exponent missing): a warning on mkdocs' logger (so that ``mkdocs build --strict`` fails) naming the page and
    the formula."""
    with caplog.at_level(logging.WARNING, logger="mkdocs"):
        hooks.render_maths(page(f"$${tex}$$"), "tour/x.md")
    (record,) = caplog.records
    assert record.name.startswith("mkdocs.") and "tour/x.md" in record.getMessage() and tex in record.getMessage()
