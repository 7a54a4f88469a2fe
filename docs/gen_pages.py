"""The generated pages of the site, written by mkdocs-gen-files when the site is built (``make docs``).

* ``reference/``: one API page per public module of ``src/pkm`` (no ``_private`` module), a package's page being its
  section's index, and ``reference/SUMMARY.md`` (literate-nav) as the section's navigation. A package page renders the package's docstring and its own definitions, then a table of
  the names it re-exports, each linked to the page of the module that defines it (where it is documented once).
  The package ``pkm`` re-exports every name of ``pkm.__all__``: ``tests/test_docs.py`` checks the table covers it.
* ``gallery.md``: the report's figures when ``make demo`` has made them (``out/figures/<paper>/*.png``, copied into
  the site), otherwise a page saying how to make them. The build never runs the report.

The functions return ``{path: text}`` (and the gallery's images as ``{path: source}``) so that the test can read the
pages without building the site; run as a script (``python docs/gen_pages.py``) it prints the API pages' paths.
"""

from __future__ import annotations

import importlib
import os
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SRC = ROOT / "src"

# ---------------------------------------------------------------------------------------------------- API pages


def public_modules() -> list[str]:
    """Every public module of ``src/pkm``, sorted: no ``_private`` part, no ``__main__``."""
    names = []
    for path in sorted(SRC.joinpath("pkm").rglob("*.py")):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        if any(part.startswith("_") for part in parts):
            continue
        names.append(".".join(parts))
    return sorted(names)


def page_of(module: str, packages: set[str]) -> str:
    """The page of ``module``: ``reference/pkm/core/index.md`` for a package, ``reference/pkm/core/spec.md``."""
    parts = module.split(".")
    return "reference/" + "/".join(parts) + ("/index.md" if module in packages else ".md")


def _griffe_package():
    import griffe

    return griffe.load("pkm", search_paths=[str(SRC)], allow_inspection=False, docstring_parser="google")


def _packages() -> set[str]:
    return {".".join(p.parent.relative_to(SRC).parts) for p in SRC.joinpath("pkm").rglob("__init__.py")}


def reexports(module: str, griffe_module) -> dict[str, str]:
    """The names package ``module`` re-exports, each with the path of the object it stands for (where it is
    documented): its ``__all__`` (read statically by griffe, or at run time when it is computed, as in the lazy
    packages ``pkm`` and ``pkm.core``: importing them is cheap) less its own definitions."""
    exports = griffe_module.exports
    if not exports:
        exports = getattr(importlib.import_module(module), "__all__", ())
    out = {}
    for name in sorted(str(n) for n in exports):
        member = griffe_module.members.get(name)
        if member is not None and not member.is_alias and member.is_module:  # a submodule it exports (pkm.errors)
            out[name] = member.path
            continue
        if member is None or not member.is_alias:
            continue
        try:
            out[name] = member.final_target.path
        except Exception:  # (a name the module makes at run time, by its __getattr__: its module is documented)
            out[name] = member.target_path.rpartition(".")[0]
    return out


def _defined_in(name: str, target: str, is_module: bool) -> str:
    """The re-exports table's "defined in" cell: the defining module (``pkm.core.kinematics.solve`` for ``solve_ik``),
    the full path where the object has another name there or is itself a module. (The name links to the object; the
    cell stays short so that the table leaves its summary room.)"""
    module, _, leaf = target.rpartition(".")
    return target if is_module or leaf != name or not module else module


def _role_text(role: str, target: str) -> str:
    """A reST role in a table cell: ``:math:`x``` as maths, ``:class:`~pkm.a.B``` as code ``B`` (the last name, as
    Sphinx shows it), ``:func:`pkm.a.b``` as code of its whole target."""
    if role.startswith(":math:"):
        return f"\\({target}\\)"
    return f"`{target.rpartition('.')[2] if '`~' in role else target}`"


def _summary(obj) -> str:
    doc = obj.docstring.value if obj.docstring else ""
    first = doc.strip().split("\n\n")[0].replace("\n", " ").strip()
    # (no ``~pkm.a.b.C`` path left whole: a word that long keeps the summary column from narrowing)
    first = re.sub(r":[a-z]+:`~?([^`]*)`", lambda m: _role_text(m.group(0), m.group(1)), first)
    return first.replace("|", r"\|")


def api_pages() -> dict[str, str]:
    """``{path: markdown}`` of the API reference, with ``reference/SUMMARY.md``."""
    sys.path.insert(0, str(SRC))
    pkg = _griffe_package()
    packages = _packages()
    pages: dict[str, str] = {}
    nav: list[str] = []
    for module in public_modules():
        gmod = pkg if module == "pkm" else pkg[module.removeprefix("pkm.")]
        path = page_of(module, packages)
        depth = module.count(".")
        nav.append("    " * depth + f"* [{module}]({path.removeprefix('reference/')})")
        if module not in packages:
            pages[path] = f"# `{module}`\n\n::: {module}\n    options:\n      show_root_heading: false\n"
            continue
        own = [n for n, m in gmod.members.items() if not m.is_alias and not n.startswith("_") and not m.is_module]
        text = f"# `{module}`\n\n::: {module}\n    options:\n      show_root_heading: false\n"
        text += f"      members: {own!r}\n" if own else "      members: false\n"
        exported = reexports(module, gmod)
        if exported:
            text += (f"\n## Names re-exported by `{module}`\n\nEach is documented in the module that defines it "
                     "(the name links there).\n\n| name | defined in | summary |\n|---|---|---|\n")
            for name, target in exported.items():
                obj = pkg[target.removeprefix("pkm.")] if target != "pkm" else pkg
                text += f"| [`{name}`][{target}] | `{_defined_in(name, target, obj.is_module)}` | {_summary(obj)} |\n"
        pages[path] = text
    pages["reference/SUMMARY.md"] = "\n".join(nav) + "\n"
    return pages


# ------------------------------------------------------------------------------------------------------ gallery


def gallery_pages(figures: Path | None = None) -> tuple[dict[str, str], dict[str, Path]]:
    """``({"gallery.md": markdown}, {site path: png})``: the figures ``make demo`` wrote into ``out/figures``,
    by paper, or a page saying how to make them when there are none."""
    if figures is None:  # (PKM_DOCS_FIGURES: another folder, such as an empty one to see the page without figures)
        figures = Path(os.environ.get("PKM_DOCS_FIGURES") or ROOT / "out" / "figures")
    pngs = sorted(figures.glob("*/*.png")) if figures.is_dir() else []
    text = ("# Gallery\n\nThe figures of the four papers, redrawn by pkm's report (`make demo`, or "
            "`pkm report --out out`: `out/figures/<paper>/*.png`; each paper's `figures(out_dir)` in `pkm.papers`). "
            "The site shows those found in `out/figures` when it is built; it never runs the report.\n")
    images: dict[str, Path] = {}
    if not pngs:
        text += ("\n!!! note \"No figures yet\"\n    `out/figures` is empty or absent in this checkout: run `make demo` "
                 "(a few minutes), then `make docs` again.\n")
        return {"gallery.md": text}, images
    paper = None
    for png in pngs:
        if png.parent.name != paper:
            paper = png.parent.name
            text += f"\n## {paper}\n\nModule [`pkm.papers.{paper}`][pkm.papers.{paper}].\n" if (
                SRC / "pkm" / "papers" / f"{paper}.py").exists() else f"\n## {paper}\n"
        site_path = f"gallery/{paper}/{png.name}"
        images[site_path] = png
        caption = png.stem.replace("_", " ")
        text += f"\n<figure markdown>\n![{caption}]({site_path}){{ loading=lazy }}\n<figcaption>{png.name}</figcaption>\n</figure>\n"
    return {"gallery.md": text}, images


# --------------------------------------------------------------------------------------------------------- main


def write() -> None:
    """Write every generated page into the build (mkdocs-gen-files)."""
    import mkdocs_gen_files

    gallery, images = gallery_pages()
    for path, text in {**api_pages(), **gallery}.items():
        with mkdocs_gen_files.open(path, "w") as f:
            f.write(text)
    for path, source in images.items():
        with mkdocs_gen_files.open(path, "wb") as f:
            f.write(source.read_bytes())
    mkdocs_gen_files.set_edit_path("gallery.md", "docs/gen_pages.py")


if __name__ == "__main__":
    print("\n".join(sorted(api_pages())))
elif __name__ == "<run_path>":  # (mkdocs-gen-files runs the script with runpy.run_path)
    write()
