"""A real service for the suite: uvicorn on a free port of 127.0.0.1 in a thread, started once per session with a
token, stopped at the end (its graceful shutdown)."""

from __future__ import annotations

import threading
import time

import pytest

pytest.importorskip("fastapi")
pytest.importorskip("uvicorn")

TOKEN = "test-token"


class Server:
    def __init__(self, app):
        import uvicorn

        from pkm.serve.process import free_port

        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self.server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=self.port, log_level="warning"))
        self.thread = threading.Thread(target=self.server.run, daemon=True)

    def __enter__(self) -> Server:
        self.thread.start()
        for _ in range(400):
            if self.server.started:
                return self
            time.sleep(0.025)
        raise RuntimeError("the service did not start")

    def __exit__(self, *exc) -> None:
        self.server.should_exit = True
        self.thread.join(timeout=30)


@pytest.fixture(scope="session")
def service(tmp_path_factory):
    from pkm.serve.app import create_app
    from pkm.serve.store import Store

    folder = tmp_path_factory.mktemp("store")
    app = create_app(Store(folder), token=TOKEN, workers=2, queue=8, max_body=2**20)
    with Server(app) as s:
        s.store_folder = folder
        yield s


@pytest.fixture(scope="session")
def client(service):
    from pkm.client import Client

    with Client(service.url, token=TOKEN) as c:
        yield c
