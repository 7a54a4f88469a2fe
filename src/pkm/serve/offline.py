"""The service's API docs without a network: Swagger UI at ``/docs`` and ReDoc at ``/redoc``, served by pkm.

FastAPI's own ``/docs`` and ``/redoc`` load Swagger UI and ReDoc from a CDN (jsDelivr), their favicon from
fastapi.tiangolo.com and ReDoc's fonts from Google: a blank page on a robot or in a lab without internet. Here the
same two pages (:func:`fastapi.openapi.docs.get_swagger_ui_html`, :func:`fastapi.openapi.docs.get_redoc_html`) load
the JavaScript, CSS and favicon that the ``fastapi-offline`` package ships (part of the ``serve`` extra), mounted at
:data:`STATIC`; ReDoc without Google Fonts, Swagger UI without its online validator badge (``validatorUrl``
None). ReDoc's bundle draws its sidebar's "API docs by Redocly" logo from cdn.redoc.ly, with no option to turn it
off: pkm serves that bundle with the logo's address (:data:`REDOC_LOGO`) replaced by an empty picture. Nothing the
pages load leaves the machine (``tests/serve/test_offline.py`` checks it in Chromium with the outside network
blocked).

With a token (``pkm serve --token``), the pages are behind it like every route but ``/`` and ``/health``: a browser
opens ``/docs?token=<token>`` (the service takes ``?token=`` on a GET), and the page passes the token it was opened
with on to what it loads (the static files and ``/openapi.json``), so that no route has to be exempted from the
token: the service shows nothing, not even its schema, to a client without it. Swagger UI's "Try it out" sends the
``Authorization: Bearer`` header once the token is given to its Authorize button (the schema declares the bearer
scheme on every operation but ``/`` and ``/health`` when the service has a token).
"""

# (no ``from __future__ import annotations``: FastAPI reads the routes' annotations)
from typing import Any
from urllib.parse import quote

#: Where the pages' static files (Swagger UI's and ReDoc's JavaScript and CSS, the favicon) are served.
STATIC = "/docs-static"
#: The one outside address ReDoc's bundle loads (its logo), and what pkm's copy has instead.
REDOC_LOGO = ("https://cdn.redoc.ly/redoc/logo-mini.svg", "data:image/svg+xml,%3Csvg xmlns='http://www.w3.org/2000/svg'/%3E")


def add_offline_docs(app: Any, docs_url: str = "/docs", redoc_url: str = "/redoc") -> None:
    """Add Swagger UI at ``docs_url`` and ReDoc at ``redoc_url`` to ``app``, from local files (see the module doc).

    Args:
        app: A :class:`fastapi.FastAPI` made with ``docs_url=None, redoc_url=None`` (FastAPI's CDN pages off).
        docs_url: The Swagger UI page's path.
        redoc_url: The ReDoc page's path.
    """
    from pkm._optional import require

    require("serve", "the service's API docs (/docs, /redoc)")
    from pathlib import Path

    import fastapi_offline
    from fastapi import Request
    from fastapi.openapi.docs import get_redoc_html, get_swagger_ui_html
    from fastapi.responses import HTMLResponse, Response
    from fastapi.staticfiles import StaticFiles

    static = Path(fastapi_offline.__file__).parent / "static"
    redoc_js: list[bytes] = []  # (read on the first request)

    @app.get(f"{STATIC}/redoc.js", include_in_schema=False)  # (before the mount, which would answer it otherwise)
    async def redoc_bundle() -> Response:
        if not redoc_js:
            redoc_js.append((static / "redoc.standalone.js").read_bytes().replace(
                REDOC_LOGO[0].encode(), REDOC_LOGO[1].encode()))
        return Response(redoc_js[0], media_type="text/javascript", headers={"cache-control": "max-age=3600"})

    app.mount(STATIC, StaticFiles(directory=static), name="docs-static")

    def urls(request: Request) -> tuple[str, str, str]:
        """The page's root, the query string passing its token on ("" without one) and the schema's URL."""
        root = request.scope.get("root_path", "")
        token = request.query_params.get("token")
        tail = "" if token is None else f"?token={quote(token, safe='')}"  # (quoted: no quote or < in the page)
        return root, tail, f"{root}{app.openapi_url}{tail}"

    @app.get(docs_url, include_in_schema=False)
    async def swagger_ui(request: Request) -> HTMLResponse:
        root, tail, schema = urls(request)
        return get_swagger_ui_html(
            openapi_url=schema, title=f"{app.title} - Swagger UI",
            swagger_js_url=f"{root}{STATIC}/swagger-ui-bundle.js{tail}",
            swagger_css_url=f"{root}{STATIC}/swagger-ui.css{tail}",
            swagger_favicon_url=f"{root}{STATIC}/favicon.png{tail}",
            swagger_ui_parameters={**(app.swagger_ui_parameters or {}), "validatorUrl": None})

    @app.get(redoc_url, include_in_schema=False)
    async def redoc(request: Request) -> HTMLResponse:
        root, tail, schema = urls(request)
        return get_redoc_html(
            openapi_url=schema, title=f"{app.title} - ReDoc", redoc_js_url=f"{root}{STATIC}/redoc.js{tail}",
            redoc_favicon_url=f"{root}{STATIC}/favicon.png{tail}", with_google_fonts=False)


__all__ = ["REDOC_LOGO", "STATIC", "add_offline_docs"]
