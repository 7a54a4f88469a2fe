"""The documentation site (``make docs``) documents every public name of ``pkm``.

Cheap by default: each name of ``pkm.__all__`` is followed statically (the sources' imports, read with ``ast``) to the
module that defines it, which must have an API page (``docs/gen_pages.py``) that renders it; with griffe installed
(the ``docs`` extra), the generated ``pkm`` page must also list and link it. ``PKM_DOCS=1`` builds the site
(``mkdocs build --strict``, about 10 s) and checks each name's anchor in the HTML.
"""

from __future__ import annotations

import ast
import importlib.util
import os
import re
import sys
from pathlib import Path

import pytest
import yaml

import pkm
from tests import bounded

ROOT = Path(__file__).resolve().parent.parent
SRC = ROOT / "src"


def _gen_pages():
    spec = importlib.util.spec_from_file_location("pkm_docs_gen_pages", ROOT / "docs" / "gen_pages.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class _ConfigLoader(yaml.SafeLoader):
    """mkdocs.yml's YAML: MkDocs' own tags (``!ENV``, ``!!python/name:``) read as None."""


_ConfigLoader.add_multi_constructor("!", lambda loader, suffix, node: None)
_ConfigLoader.add_multi_constructor("tag:yaml.org,2002:python/", lambda loader, suffix, node: None)


def _mkdocs_config() -> dict:
    return yaml.load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"), Loader=_ConfigLoader)


def _source(module: str) -> Path | None:
    base = SRC.joinpath(*module.split("."))
    for path in (base.with_suffix(".py"), base / "__init__.py"):
        if path.exists():
            return path
    return None


def _tree(module: str) -> ast.Module:
    return ast.parse(_source(module).read_text(encoding="utf-8"))


def _static_all(tree: ast.Module) -> list[str] | None:
    """A module's ``__all__`` when it is a literal list (what griffe reads), else None."""
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets):
            try:
                return list(ast.literal_eval(node.value))
            except ValueError:
                return None
    return None


def resolve(module: str, name: str, depth: int = 0) -> tuple[str, str | None]:
    """``(defining module, name there)`` of ``module.name``, following imports (those under ``TYPE_CHECKING``
    too, as griffe does); ``(module, None)`` when the name is a module."""
    assert depth < 20, f"import cycle at {module}.{name}"
    if _source(f"{module}.{name}") is not None:
        return f"{module}.{name}", None
    tree = _tree(module)
    for node in tree.body:  # defined here
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) and node.name == name:
            return module, name
        targets = node.targets if isinstance(node, ast.Assign) else [node.target] if isinstance(
            node, ast.AnnAssign) else []
        if any(isinstance(t, ast.Name) and t.id == name for t in targets):
            return module, name
    for node in ast.walk(tree):  # imported here
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            for alias in node.names:
                if (alias.asname or alias.name) == name:
                    return resolve(node.module, alias.name, depth + 1)
    raise AssertionError(f"{module}.{name}: not found in the sources")


def test_every_public_name_has_a_rendered_home():
    """Each name of ``pkm.__all__`` is defined in a module with an API page, where mkdocstrings renders it (a
    public name, in the module's ``__all__`` when it has a literal one)."""
    modules = set(_gen_pages().public_modules())
    assert "pkm" in modules
    for name in pkm.__all__:
        module, obj = resolve("pkm", name)
        assert module in modules, f"pkm.{name} is defined in {module}, which has no API page"
        if obj is None:
            continue
        assert not obj.startswith("_"), f"pkm.{name} is {module}.{obj}, a private name: not rendered"
        exported = _static_all(_tree(module))
        assert exported is None or obj in exported, f"pkm.{name}: {module}.{obj} is not in {module}.__all__"


def test_private_modules_have_no_page():
    modules = _gen_pages().public_modules()
    assert "pkm.core.kinematics.solve" in modules and "pkm.core" in modules
    assert not any(part.startswith("_") for m in modules for part in m.split("."))


def test_the_pkm_page_lists_every_public_name():
    pytest.importorskip("griffe")
    gen = _gen_pages()
    pages = gen.api_pages()
    text = pages["reference/pkm/index.md"]
    assert "::: pkm\n" in text
    for name in pkm.__all__:
        module, obj = resolve("pkm", name)
        target = module if obj is None else f"{module}.{obj}"
        own = f"'{name}'" in text.split("members:")[1].split("\n")[0]
        assert own or f"| [`{name}`][{target}] |" in text, f"pkm.{name} is not listed on pkm's page"
    summary = pages["reference/SUMMARY.md"]
    for module in gen.public_modules():
        assert f"[{module}](" in summary


def test_the_reexports_table_keeps_names_whole():
    """The re-exports table: each name linked to its definition, its module in the "defined in" cell (not the full
    path again), the summaries' roles as Sphinx shows them (``:class:`~pkm.a.B``` as ``B``), and inline code in tables
    that breaks at no letter (Material's ``word-break: break-word`` let the
    table squeeze its name columns to a few characters: ``task_accel|eration``)."""
    pytest.importorskip("griffe")
    text = _gen_pages().api_pages()["reference/pkm/index.md"]
    assert "| [`solve_ik`][pkm.core.kinematics.solve.solve_ik] | `pkm.core.kinematics.solve` |" in text
    assert "| [`errors`][pkm.errors] | `pkm.errors` |" in text  # (a module: its own path)
    assert "~pkm." not in text and "(an `Estimate` or a `ConsistentEstimate`)" in text  # (roles as Sphinx shows them)
    config = _mkdocs_config()
    assert "stylesheets/pkm.css" in config["extra_css"]
    css = (ROOT / "docs" / "stylesheets" / "pkm.css").read_text(encoding="utf-8")
    assert re.search(r"table:not\(\[class\]\) code \{\s*word-break: normal;", css)


def test_the_tour_is_in_the_nav():
    """Every page of ``docs/tour/`` is in ``mkdocs.yml``'s nav, and every page the nav names exists."""
    nav = _mkdocs_config()["nav"]
    tour = next(entry["Tour"] for entry in nav if "Tour" in entry)
    listed = {item if isinstance(item, str) else next(iter(item.values())) for item in tour}
    files = {f"tour/{p.name}" for p in (ROOT / "docs" / "tour").glob("*.md")}
    assert listed == files and "tour/index.md" in files


def test_gallery_without_figures_says_how_to_make_them(tmp_path):
    pages, images = _gen_pages().gallery_pages(tmp_path / "absent")
    assert images == {} and "make demo" in pages["gallery.md"]


@pytest.mark.skipif(os.environ.get("PKM_DOCS") != "1", reason="builds the site: set PKM_DOCS=1 (make docs builds it)")
def test_site_builds_strict_and_documents_every_name(tmp_path):
    pytest.importorskip("mkdocs")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1", "DISABLE_MKDOCS_2_WARNING": "true"}
    out = bounded.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "-d", str(tmp_path / "site")],
                      cwd=ROOT, env=env, cpu=300)
    assert out.returncode == 0, out.stderr[-4000:]
    for name in pkm.__all__:
        module, obj = resolve("pkm", name)
        page = tmp_path / "site" / "reference" / Path(*module.split("."))
        html = (page / "index.html").read_text(encoding="utf-8")
        anchor = module if obj is None else f"{module}.{obj}"
        assert f'id="{anchor}"' in html, f"pkm.{name}: no anchor {anchor} in {page}"
