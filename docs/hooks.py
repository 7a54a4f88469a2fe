"""MkDocs hook: the docstrings' reST roles, rendered, and every formula typeset at build time (no network).

pkm's docstrings are Google style with reST inline markup in places: ``double backticks`` (which Markdown reads as
code already) and roles such as :func:`pkm.close_loops`, :class:`...`, :mod:`...`, :math:`...`. Markdown turns a role
into the text ``:func:`` followed by code; this hook, run on each page's HTML before mkdocs-autorefs resolves the
cross-references, makes

* ``:func:`x``` (and ``:class:``, ``:meth:``, ``:mod:``, ``:attr:``, ``:data:``, ``:exc:``, ``:obj:``) an *optional*
  cross-reference to ``x``: a link where ``x`` is documented on the site, plain code otherwise (no warning). A name
  that is not a full path (``:func:`load```) is tried inside the page's module first (``pkm.load`` on ``pkm``'s page);
  ``:func:`~pkm.core.model.builder.build``` shows ``build``, as in Sphinx;
* ``:math:`x``` inline maths.

The maths, those roles and pymdownx.arithmatex's (``$x$``, ``$$ ... $$``, ``\\(x\\)``, ``\\[x\\]``, its generic
output: ``<span class="arithmatex">\\(x\\)</span>``, ``<div class="arithmatex">\\[x\\]</div>``), is turned into
MathML here, when the site is built, by latex2mathml (the ``docs`` extra; pure Python): browsers render MathML
themselves (Chromium since 109, Firefox, Safari), so that the site shows its formulas without loading MathJax or
KaTeX from a CDN, offline. TeX that latex2mathml cannot render (a command it does not know, which it would print as
text, such as ``\\arg``; an ``&`` outside a matrix-like environment) is a warning naming the page and the formula,
so that ``mkdocs build --strict`` fails rather than showing raw TeX.
"""

from __future__ import annotations

import html
import logging
import re

_ROLE = re.compile(r":(func|class|meth|mod|attr|data|exc|obj|const):<code>(?P<target>[^<]*)</code>")
_MATH = re.compile(r":math:<code>(?P<tex>[^<]*)</code>")
_ARITHMATEX = re.compile(r'<(?P<tag>span|div) class="arithmatex">(?P<tex>.*?)</(?P=tag)>', re.DOTALL)
_TEXT = re.compile(r">([^<]+)<")  # (the text between MathML's tags)
log = logging.getLogger("mkdocs.hooks.pkm")  # (under mkdocs': a warning fails a --strict build)


def mathml(tex: str, display: bool = False, where: str = "") -> str:
    """The MathML of the TeX ``tex`` (``display``: a block, else inline); a warning (``where``: the page) when
    latex2mathml leaves part of it unrendered."""
    from latex2mathml.converter import convert

    try:
        out = convert(tex.strip(), display="block" if display else "inline")
    except Exception as e:  # (latex2mathml's own errors: an unbalanced brace, a missing argument ...)
        log.warning("%s: the formula `%s` cannot be rendered: %s: %s", where, tex, type(e).__name__, e)
        return f"<code>{html.escape(tex)}</code>"
    left = [t for t in _TEXT.findall(out) if "\\" in t or re.search(r"&(?!#?\w+;)", t)]
    if left:
        log.warning("%s: latex2mathml leaves %s of the formula `%s` as text", where, " ".join(left), tex)
    return out


def render_maths(content: str, where: str = "") -> str:
    """``content`` (a page's HTML) with pymdownx.arithmatex's formulas (generic output) as MathML."""

    def formula(match: re.Match) -> str:
        tex = html.unescape(match["tex"]).strip()
        if tex.startswith("\\(") and tex.endswith("\\)"):
            return mathml(tex[2:-2], False, where)
        if tex.startswith("\\[") and tex.endswith("\\]"):
            tex = tex[2:-2]
        # (a block in Material's style, scrolling sideways if it is wide; no vertical scroll bar for a tall one)
        return f'<div class="arithmatex" style="overflow-y: hidden">{mathml(tex, True, where)}</div>'

    return _ARITHMATEX.sub(formula, content)


def _module_of(url: str) -> str | None:
    """``pkm.core.model.spec`` for the API page ``reference/pkm/core/model/spec/`` (None for other pages)."""
    if not url.startswith("reference/pkm"):
        return None
    return url.removeprefix("reference/").strip("/").replace("/", ".") or None


def render_roles(content: str, module: str | None = None, where: str = "") -> str:
    """``content`` (a page's HTML) with its reST roles as optional cross-references and inline maths (MathML;
    ``where``: the page, for warnings)."""

    def role(match: re.Match) -> str:
        target = html.unescape(match["target"]).strip()
        shown = target.lstrip("~.!")
        title = f"<code>{html.escape(shown.rpartition('.')[2] if target.startswith('~') else shown)}</code>"
        if not re.fullmatch(r"[\w.]+", shown):
            return title
        if module and not shown.startswith("pkm"):  # relative: the page's module first, then as written
            return f'<autoref identifier="{module}.{shown}" slug="{shown}" optional>{title}</autoref>'
        return f'<autoref identifier="{shown}" optional>{title}</autoref>'

    def math(match: re.Match) -> str:
        return mathml(html.unescape(match["tex"]), False, where)

    return _MATH.sub(math, _ROLE.sub(role, content))


def on_page_content(html_: str, page, **kwargs) -> str:
    """The MkDocs event: each page's HTML, after Markdown, before mkdocs-autorefs resolves the references."""
    where = page.file.src_uri
    return render_maths(render_roles(html_, _module_of(page.url), where), where)
