"""``tools/offline_site.py`` (run by CI on the built docs site) finds what it looks for: on a small site written here,
a page that loads a CDN's script, a page showing raw TeX, a page without an h1 and a formula with no size are each
reported, and a page with typeset maths (MathML) and nothing from outside is not. The session's Chromium
(``offline_browser``; skipped without it unless ``PKM_REQUIRE_BROWSER`` is set)."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))
import offline_site  # (tools/ is no package: imported from its folder)

MATH = '<math display="inline"><mfrac><mi>a</mi><mi>b</mi></mfrac></math>'
PAGES = {
    "index.html": f"<h1>Home</h1><p>the ratio {MATH}</p>",
    "cdn/index.html": '<h1>CDN</h1><script src="https://cdn.jsdelivr.net/npm/mathjax@3/es5/tex-mml-chtml.js"></script>',
    "tex/index.html": "<h1>TeX</h1><p>the ratio \\(a/b\\) and $$x$$</p>",
    "blank/index.html": "<p>no heading</p>",
    "hidden/index.html": f'<h1>Hidden</h1><p style="display: none">{MATH}</p>',
}


def test_the_site_check_reports_each_fault_and_only_those(offline_browser, tmp_path):
    site = tmp_path / "site"
    for name, body in PAGES.items():
        (site / name).parent.mkdir(parents=True, exist_ok=True)
        (site / name).write_text(f'<!DOCTYPE html><html><head><meta charset="utf-8"><link rel="icon" href="data:,">'
                                 f"</head><body>{body}</body></html>", encoding="utf-8")
    assert offline_site.pages(site) == ["blank/", "cdn/", "hidden/", "", "tex/"]
    findings, counts = offline_site.check(site, browser=offline_browser(cache=True))
    assert counts["pages"] == 5 and counts["maths"] == 2
    by_page: dict[str, list[str]] = {}
    for line in findings:
        page, _, finding = line.partition(": ")
        by_page.setdefault(page, []).append(finding)
    assert set(by_page) == {"cdn/", "tex/", "blank/", "hidden/"}, findings  # (the home page: nothing)
    assert "a request leaves 127.0.0.1: https://cdn.jsdelivr.net/npm/mathjax@3/es5/tex-mml-chtml.js" in by_page["cdn/"]
    assert by_page["tex/"] == ["raw TeX in the text: ...TeX the ratio \\(a/b\\) and $$x$$..."] * 3  # (\\(, $$ twice)
    assert by_page["blank/"] == ["no h1 (the page did not render)"]
    assert by_page["hidden/"] == ["a formula drawn with no size: ab"]
