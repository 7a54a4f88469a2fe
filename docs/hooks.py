"""MkDocs hook: the docstrings' reST roles, rendered.

pkm's docstrings are Google style with reST inline markup in places: ``double backticks`` (which Markdown reads as
code already) and roles such as :func:`pkm.close_loops`, :class:`...`, :mod:`...`, :math:`...`. Markdown turns a role
into the text ``:func:`` followed by code; this hook, run on each page's HTML before mkdocs-autorefs resolves the
cross-references, makes

* ``:func:`x``` (and ``:class:``, ``:meth:``, ``:mod:``, ``:attr:``, ``:data:``, ``:exc:``, ``:obj:``) an *optional*
  cross-reference to ``x``: a link where ``x`` is documented on the site, plain code otherwise (no warning). A name
  that is not a full path (``:func:`load```) is tried inside the page's module first (``pkm.load`` on ``pkm``'s page);
  ``:func:`~pkm.core.model.builder.build``` shows ``build``, as in Sphinx;
* ``:math:`x``` inline maths (``\\(x\\)``, typeset by MathJax through pymdownx.arithmatex's ``arithmatex`` class).
"""

from __future__ import annotations

import html
import re

_ROLE = re.compile(r":(func|class|meth|mod|attr|data|exc|obj|const):<code>(?P<target>[^<]*)</code>")
_MATH = re.compile(r":math:<code>(?P<tex>[^<]*)</code>")


def _module_of(url: str) -> str | None:
    """``pkm.core.model.spec`` for the API page ``reference/pkm/core/model/spec/`` (None for other pages)."""
    if not url.startswith("reference/pkm"):
        return None
    return url.removeprefix("reference/").strip("/").replace("/", ".") or None


def render_roles(content: str, module: str | None = None) -> str:
    """``content`` (a page's HTML) with its reST roles as optional cross-references and inline maths."""

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
        return f'<span class="arithmatex">\\({match["tex"]}\\)</span>'

    return _MATH.sub(math, _ROLE.sub(role, content))


def on_page_content(html_: str, page, **kwargs) -> str:
    """The MkDocs event: each page's HTML, after Markdown, before mkdocs-autorefs resolves the references."""
    return render_roles(html_, _module_of(page.url))
