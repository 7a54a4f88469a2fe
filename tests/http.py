"""The tests' HTTP calls to a local ``pkm serve``: httpx's module functions (``request``, ``get``, ``post``) with one
TLS context for the whole process. httpx builds a context, loading certifi's certificate store (40 to 90 ms of CPU),
for every module-level call otherwise: 137 calls, 5 to 12 s of the serve tests' CPU. The services the tests start
speak plain HTTP on 127.0.0.1, so the context is never used; each call is still a client of its own (no cookie or
connection carried from one call to the next)."""

from __future__ import annotations

import functools
import ssl
from typing import Any

import certifi
import httpx

_TLS = ssl.create_default_context(cafile=certifi.where())


def request(method: str, url: str, **kwargs: Any) -> httpx.Response:
    """``httpx.request`` with the process's TLS context."""
    kwargs.setdefault("verify", _TLS)
    return httpx.request(method, url, **kwargs)


get = functools.partial(request, "GET")
post = functools.partial(request, "POST")
