"""Every page of the built documentation site, loaded in headless Chromium with the outside network off.

Run by ``.ci/run`` right after ``make docs``::

    .venv/bin/python tools/offline_site.py [site]

It serves ``site/`` (the default) on 127.0.0.1 and loads each of its pages (every ``*.html`` file: the site's
``index.html`` pages and its 404 page) in one headless Chromium whose outside network is blocked
(:mod:`tests.browser`), and fails (exit code 1, each finding printed) when a page

* makes a request that leaves 127.0.0.1 (a CDN's script, a web font ...), or has a console error, an uncaught
  exception or a failed request;
* has no ``h1`` with text (it did not render);
* shows raw TeX: ``\\(``, ``\\[``, ``$$`` or ``:math:`` in its rendered text (``innerText``), an arithmatex
  formula left without MathML, a MathML error (``merror``), or a formula drawn with no size.

It prints the number of pages, of formulas and of requests, and its wall time. Chromium is required (Debian's
``chromium``; ``--chromium`` to give another); ``--jobs`` browsers share the pages (default: half the CPUs, at most
4).
"""

from __future__ import annotations

import argparse
import functools
import os
import shutil
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the checkout: the browser lives in tests/browser.py
from tests.browser import OfflineBrowser

RAW_TEX = ("\\(", "\\[", "$$", ":math:")

# What a page shows, in one evaluation: its h1, the raw TeX in its text (with some context), its formulas.
PROBE = """(() => {
  const text = document.body ? document.body.innerText : "";
  const raw = [];
  for (const mark of %s) {
    for (let i = text.indexOf(mark); i >= 0 && raw.length < 5; i = text.indexOf(mark, i + 1))
      raw.push(text.slice(Math.max(0, i - 30), i + 40).replace(/\\s+/g, " "));
  }
  const h1 = document.querySelector("h1");
  const maths = Array.from(document.querySelectorAll("math"));
  const shown = maths.filter(m => !m.closest("details:not([open])"));  // (a closed admonition draws nothing)
  return {
    h1: h1 ? h1.innerText.trim() : "",
    raw: raw,
    maths: maths.length,
    empty: shown.filter(m => { const r = m.getBoundingClientRect(); return !(r.width > 0 && r.height > 0); })
      .map(m => m.textContent.slice(0, 60)),
    merror: document.querySelectorAll("merror").length,
    leftover: Array.from(document.querySelectorAll(".arithmatex")).filter(e => !e.querySelector("math"))
      .map(e => e.textContent.slice(0, 60)),
  };
})()"""


def pages(site: Path) -> list[str]:
    """The site's pages as paths from its root: ``tour/`` for ``tour/index.html``, ``404.html``."""
    out = []
    for f in sorted(site.rglob("*.html")):
        rel = f.relative_to(site).as_posix()
        out.append(rel.removesuffix("index.html") if f.name == "index.html" else rel)
    return out


class _Quiet(SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: object) -> None:  # (the requests, not printed)
        pass


def _visit(browser: OfflineBrowser, url: str, name: str, timeout: float) -> tuple[list[str], dict]:
    """One page's findings and counts."""
    try:
        browser.load(url, timeout)
        browser.settle(quiet=0.1, timeout=timeout)
        seen = browser.evaluate(PROBE % repr(list(RAW_TEX)).replace("'", '"'))
    except (RuntimeError, TimeoutError) as e:
        return [f"{name}: did not load: {e}"], {"pages": 0, "maths": 0, "requests": 0}
    findings = [f"{name}: a request leaves 127.0.0.1: {u}" for u in browser.outside()]
    findings += [f"{name}: {e}" for e in browser.errors]
    if not seen["h1"]:
        findings.append(f"{name}: no h1 (the page did not render)")
    findings += [f"{name}: raw TeX in the text: ...{r}..." for r in seen["raw"]]
    findings += [f"{name}: a formula left as TeX: {t}" for t in seen["leftover"]]
    findings += [f"{name}: a formula drawn with no size: {t}" for t in seen["empty"]]
    if seen["merror"]:
        findings.append(f"{name}: {seen['merror']} MathML error(s) (merror)")
    return findings, {"pages": 1, "maths": seen["maths"], "requests": len(browser.requests)}


def check(site: Path, chromium: str | None = None, timeout: float = 30.0, jobs: int = 1,
          browser: OfflineBrowser | None = None) -> tuple[list[str], dict]:
    """The findings (one line each, in the pages' order; none: the site works offline) and the counts of the run;
    ``jobs`` browsers of the executable ``chromium`` load the pages side by side, or ``browser`` (one already started,
    its cache on, as these are) loads them all."""
    if browser is None and chromium is None:
        raise ValueError("offline_site.check: neither a Chromium executable nor a browser given")
    server = ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(_Quiet, directory=str(site)))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    base = f"http://127.0.0.1:{server.server_address[1]}/"
    names = pages(site)
    results: dict[str, tuple[list[str], dict]] = {}

    def visit(browser: OfflineBrowser, share: list[str]) -> None:
        for page in share:
            results[page] = _visit(browser, base + page, page or "/", timeout)

    def work(share: list[str]) -> None:
        with (tempfile.TemporaryDirectory(ignore_cleanup_errors=True) as folder,
              OfflineBrowser(str(chromium), Path(folder), cache=True) as browser):
            visit(browser, share)

    try:
        if browser is not None:
            visit(browser, names)
        else:
            with ThreadPoolExecutor(max(1, jobs)) as pool:
                list(pool.map(work, [names[i::max(1, jobs)] for i in range(max(1, jobs))]))
    finally:
        server.shutdown()
        server.server_close()
    findings = [f for page in names for f in results[page][0]]
    counts = {k: sum(results[page][1][k] for page in names) for k in ("pages", "maths", "requests")}
    return findings, counts


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("site", nargs="?", default="site", type=Path, help="the built site (default: site)")
    parser.add_argument("--chromium", default=shutil.which("chromium") or "/usr/bin/chromium",
                        help="the Chromium executable (default: chromium on the PATH)")
    parser.add_argument("--timeout", type=float, default=30.0, help="seconds a page may take to load [s]")
    parser.add_argument("--jobs", type=int, default=max(1, min(4, (os.cpu_count() or 2) // 2)),
                        help="browsers loading pages side by side (default: half the CPUs, at most 4)")
    args = parser.parse_args(argv)
    if not (args.site / "index.html").exists():
        print(f"offline_site: {args.site} holds no built site (index.html); run `make docs` first", file=sys.stderr)
        return 2
    if not Path(args.chromium).exists():
        print(f"offline_site: no Chromium at {args.chromium} (Debian package 'chromium', or --chromium)",
              file=sys.stderr)
        return 2
    t0 = time.perf_counter()
    findings, counts = check(args.site, args.chromium, args.timeout, args.jobs)
    pages_of: dict[str, list[str]] = {}  # (a finding on every page, such as a CDN's script, printed once)
    for line in findings:
        page, _, finding = line.partition(": ")
        pages_of.setdefault(finding, []).append(page)
    for finding, where in pages_of.items():
        more = f" and {len(where) - 3} more pages" if len(where) > 3 else ""
        print(f"offline_site: {', '.join(where[:3])}{more}: {finding}")
    print(f"offline_site: {counts['pages']} pages, {counts['maths']} formulas, {counts['requests']} requests, "
          f"{len(findings)} findings, {time.perf_counter() - t0:.1f} s ({args.jobs} browsers)")
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
