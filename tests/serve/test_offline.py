"""The service's pages work without a network: headless Chromium with the outside network off (:mod:`tests.browser`)
loads the design page, Swagger UI (``/docs``), ReDoc (``/redoc``) and a model's preview from the suite's service
(with its token): each renders (Swagger UI and ReDoc show every operation of ``/openapi.json``), no request leaves
127.0.0.1 and no console error occurs. A page asking for outside files shows that such requests are seen and
blocked. Skipped without Chromium, a failure when ``PKM_REQUIRE_BROWSER`` is set (as ``tests/test_viz_browser.py``).
"""

from __future__ import annotations

import re

import pytest

from tests import http
from tests.serve.conftest import TOKEN


@pytest.fixture
def browser(offline_browser):
    """The session's headless Chromium, its cache off (every request seen)."""
    return offline_browser()


def operations(service) -> set[str]:
    """The operationId of every operation in the service's schema."""
    schema = http.get(f"{service.url}/openapi.json", headers={"authorization": f"Bearer {TOKEN}"}).json()
    return {op["operationId"] for path in schema["paths"].values() for op in path.values()}


# (page, what shows it rendered: a JavaScript expression, truthy once it has)
PAGES = {
    "/?model=delta&": "window.pkmState && pkmState.updates >= 1 && !pkmState.busy && pkmState.errors.length === 0",
    "/docs?": "document.querySelectorAll('.opblock').length",
    "/redoc?": "document.querySelectorAll('[id*=\"operation/\"]').length",
    "/models/delta/preview?": "(c => c && c.width > 0 && c.height > 0)(document.querySelector('canvas'))",
}


@pytest.mark.parametrize("page", list(PAGES))
def test_the_services_pages_render_with_the_network_off(service, browser, page):
    browser.load(f"{service.url}{page}token={TOKEN}")
    shown = browser.wait(PAGES[page])
    browser.settle()
    assert shown, f"{page} did not render: {browser.errors}"
    assert browser.outside() == [], browser.outside()
    assert browser.errors == []
    if page == "/docs?":  # every operation of the schema, listed (ids: operations-<tag>-<operationId>)
        shown_ids = browser.evaluate("Array.from(document.querySelectorAll('.opblock')).map(e => e.id)")
        ops = operations(service)
        assert len(shown_ids) == len(ops) and all(any(i.endswith(f"-{op}") for i in shown_ids) for op in ops)
    elif page == "/redoc?":  # every operation, and ReDoc's page title: the service's name and version
        shown_ids = browser.evaluate("Array.from(document.querySelectorAll('[id*=\"operation/\"]')).map(e => e.id)")
        assert {i.rpartition("operation/")[2] for i in shown_ids} == operations(service)
        assert browser.evaluate("document.querySelector('h1').innerText").startswith("pkm")


def test_an_outside_request_is_seen_and_blocked(browser):
    """The check cannot pass by not looking: a page asking for a CDN's file, an address given as a number and
    ``localhost`` has the three requests recorded as leaving 127.0.0.1, and each failed (no network)."""
    urls = ["https://cdn.jsdelivr.net/npm/x.png", "http://93.184.216.34/y.png", "http://localhost:9/z.png"]
    browser.load("data:text/html," + "".join(f"<img src='{u}'>" for u in urls))
    browser.settle()
    assert browser.outside() == urls
    assert all(any(e.startswith("request failed") and e.endswith(u) for e in browser.errors) for u in urls)


def test_the_docs_pages_stay_behind_the_token(service):
    """Nothing is exempted from the token for the docs: without it the pages, their files and the schema are 401;
    a page opened with ``?token=`` passes it on to everything it loads (and no CDN address is in it)."""
    for path in ("/docs", "/redoc", "/openapi.json", "/docs-static/redoc.js", "/docs-static/swagger-ui.css"):
        assert http.get(f"{service.url}{path}").status_code == 401, path
    for path in ("/docs", "/redoc"):
        page = http.get(f"{service.url}{path}?token={TOKEN}")
        assert page.status_code == 200
        urls = re.findall(r"""(?:src|href|url|spec-url)[=:]\s*["']([^"']+)["']""", page.text)
        assert len(urls) >= 3 and all(u.startswith("/") and u.endswith(f"?token={TOKEN}") for u in urls), urls
