"""The HTTP and WebSocket service (``pkm serve``): FastAPI on uvicorn (the ``serve`` extra).

Why FastAPI: it is Starlette (the ASGI toolkit: routing, WebSockets, multipart) plus the OpenAPI schema
(``/openapi.json``) and its browsable docs (``/docs``) generated from the routes, which the issue asks for; uvicorn
is its maintained server (graceful shutdown on SIGTERM: in-flight requests finish, new ones are refused).

Endpoints (see ``/docs``): ``GET /health``; ``GET /models``; ``POST /models`` (an upload: multipart files);
``GET /models/{model}`` (sizes, names, units); ``GET /models/{model}/files``; ``DELETE /models/{model}``; ``GET /models/{model}/parameters`` and
``POST /models/{model}/variants`` (a registered mechanism with other design parameters);
``GET /models/{model}/preview`` (the self-contained 3-D page); ``GET /`` (the design page,
:mod:`pkm.serve.page`); ``POST /models/{model}/{query}`` for every query of
:data:`pkm.serve.queries.QUERIES` (one sample or a batch); jobs (every assembly or working mode, a workspace map:
:mod:`pkm.serve.jobs`) at ``POST /models/{model}/jobs/{kind}``, ``GET /jobs/{id}`` and its ``/result``,
``DELETE /jobs/{id}``; ``WS /models/{model}/stream`` (actuator samples in, the
forward kinematics, task rates and efforts out, warm-started along the stream).

Bodies are JSON, or msgpack (``Content-Type: application/msgpack``; numpy arrays as msgpack extension 1: dtype,
shape and raw bytes, no text round trip); answers are JSON unless ``Accept`` asks for msgpack. Every answer of a
query carries ``compute_s``, the server's time for it.

Reliability: pkm's errors are 4xx answers with their message and data (422; 404 for an unknown model or query),
never a traceback; a body over ``max_body`` bytes is 413; a bearer token, when set, is required on everything but
``/health`` (401); at most ``workers`` queries compute at once and ``queue`` wait, the next is 429; a query computing longer than ``compute_limit`` seconds is answered 503.
"""

# (no ``from __future__ import annotations`` here: FastAPI reads the routes' annotations, whose types are imported
# inside create_app, when pkm[serve] is known to be installed)
import asyncio
import json
import signal
import time
from collections.abc import Callable
from typing import Any

from pkm.errors import PkmError, UnknownNameError
from pkm.report import jsonable
from pkm.serve.store import Store
from pkm.serve.wire import MSGPACK, pack, unpack


def _error(status: int, kind: str, message: str, data: Any = None) -> Any:
    from fastapi.responses import JSONResponse

    return JSONResponse({"error": kind, "message": message, "data": jsonable(data)}, status_code=status)


def _pkm_error(e: PkmError) -> Any:
    data = {k: v for k, v in vars(e).items() if isinstance(v, (str, int, float, list, tuple, dict, type(None)))}
    return _error(404 if isinstance(e, UnknownNameError) else 422, type(e).__name__, str(e), data)


class SizeLimit:
    """ASGI middleware refusing request bodies over ``max_body`` bytes (413), by Content-Length and by counting."""

    def __init__(self, app: Any, max_body: int):
        self.app, self.max_body = app, max_body

    async def __call__(self, scope: dict, receive: Callable, send: Callable) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        too_large = _error(413, "PayloadTooLarge", f"the body is over {self.max_body} bytes")
        length = dict(scope.get("headers") or []).get(b"content-length")
        if length is not None and (not length.isdigit() or int(length) > self.max_body):
            await too_large(scope, receive, send)
            return
        seen = 0

        async def counted() -> dict:
            nonlocal seen
            message = await receive()
            seen += len(message.get("body", b""))
            if seen > self.max_body:
                raise _TooLarge
            return message

        try:
            await self.app(scope, counted, send)
        except _TooLarge:
            await too_large(scope, receive, send)


class _TooLarge(Exception):
    pass


class _Busy(Exception):
    pass


class _TooSlow(Exception):
    pass


class Limiter:
    """At most ``workers`` computations at once (threads) and ``queue`` waiting; over that, :meth:`run` raises
    :class:`_Busy` (answered 429)."""

    def __init__(self, workers: int, queue: int):
        self.slots = asyncio.Semaphore(workers)
        self.queue, self.waiting = queue, 0

    async def run(self, fn: Callable[[], Any], timeout: float | None = None) -> Any:
        """``fn()`` on a thread, once a slot is free; past ``timeout`` seconds :class:`_TooSlow` is raised while the
        computation goes on, holding its slot until it ends (Python cannot stop a thread)."""
        if self.waiting >= self.queue:
            raise _Busy(f"{self.waiting} requests are waiting; try again shortly")
        self.waiting += 1
        try:
            await self.slots.acquire()
        finally:
            self.waiting -= 1
        task = asyncio.ensure_future(asyncio.to_thread(fn))
        try:
            done, _ = await asyncio.wait({task}, timeout=timeout)
        except BaseException:  # (the request cancelled: the slot is freed when the thread ends)
            task.add_done_callback(lambda _: self.slots.release())
            raise
        if not done:
            task.add_done_callback(lambda _: self.slots.release())
            raise _TooSlow(f"the computation takes more than {timeout:g} s (the service's compute-time limit); "
                           "send fewer samples, or start a job")
        self.slots.release()
        return task.result()


def create_app(store: Store | None = None, *, token: str | None = None, workers: int = 2, queue: int = 64,
               max_body: int = 32 * 2**20, job_workers: int = 1, compute_limit: float = 60.0) -> Any:
    """The service's ASGI application (see the module doc).

    Args:
        store: The models (default: the registered mechanisms, uploads in memory).
        token: The bearer token every request but ``/health`` must carry (None: none asked).
        workers: Queries computed at once (threads).
        queue: Queries waiting at most; the next is answered 429.
        max_body: Largest request body [bytes]; larger is 413.
        job_workers: Jobs run at once (:mod:`pkm.serve.jobs`), on threads apart from the queries'.
        compute_limit: A query computing longer is answered 503 [s] (it finishes in its thread, holding its slot);
            jobs have no such limit.
    """
    from pkm._optional import require

    require("serve", "the service (pkm serve)")
    from fastapi import FastAPI, Request, WebSocket, WebSocketDisconnect
    from fastapi.exceptions import RequestValidationError
    from fastapi.responses import HTMLResponse, JSONResponse, Response
    from starlette.exceptions import HTTPException as StarletteHTTPException

    from pkm import __version__
    from pkm.serve.jobs import JobManager
    from pkm.serve.offline import add_offline_docs
    from pkm.serve.queries import QUERIES, describe

    store = Store() if store is None else store
    limiter = Limiter(workers, queue)
    jobs = JobManager(job_workers)
    app = FastAPI(title="pkm", version=__version__,
                  description="Kinematics and dynamics of closed-loop mechanisms: models, queries, streams.",
                  docs_url=None, redoc_url=None)
    add_offline_docs(app)  # (/docs and /redoc from local files, not FastAPI's CDN: pkm.serve.offline)

    def answer(request: Request, payload: Any, status: int = 200) -> Response:
        if MSGPACK in request.headers.get("accept", ""):
            return Response(pack(payload), media_type=MSGPACK, status_code=status)
        return JSONResponse(jsonable(payload), status_code=status)

    async def body_of(request: Request) -> dict:
        raw = await request.body()
        try:
            if request.headers.get("content-type", "").startswith(MSGPACK):
                body = unpack(raw)
            else:
                body = json.loads(raw or b"{}")
        except Exception as e:  # (any decoding failure is the client's: msgpack, JSON, UTF-8, arrays)
            raise _BadBody(f"the body cannot be decoded: {type(e).__name__}: {str(e)[:200]}") from None
        if not isinstance(body, dict):
            raise _BadBody("the body must be an object (a map of names to values)")
        return body

    @app.exception_handler(PkmError)
    async def pkm_errors(request: Request, e: PkmError) -> Any:
        return _pkm_error(e)

    @app.exception_handler(_Busy)
    async def busy(request: Request, e: _Busy) -> Any:
        return _error(429, "Busy", str(e))

    @app.exception_handler(_TooSlow)
    async def too_slow(request: Request, e: _TooSlow) -> Any:
        return _error(503, "ComputeTimeLimit", str(e))

    @app.exception_handler(_BadBody)
    async def bad_body(request: Request, e: _BadBody) -> Any:
        return _error(400, "BadBody", str(e))

    @app.exception_handler(RequestValidationError)
    async def invalid(request: Request, e: RequestValidationError) -> Any:
        return _error(422, "InvalidRequest", "the request does not match the endpoint", e.errors())

    @app.exception_handler(Exception)
    async def unexpected(request: Request, e: Exception) -> Any:  # (a bug: said so, without a traceback)
        return _error(500, type(e).__name__, f"unexpected: {str(e)[:300]}")

    @app.middleware("http")
    async def auth(request: Request, call_next: Callable) -> Any:
        given = request.headers.get("authorization") == f"Bearer {token}" \
            or (request.method == "GET" and request.query_params.get("token") == token)  # (a page's iframe)
        if token is not None and request.url.path not in ("/", "/health") and not given:
            return _error(401, "Unauthorized", "give the service's token: Authorization: Bearer <token>")
        return await call_next(request)

    app.add_middleware(SizeLimit, max_body=max_body)  # (added last: the outermost, before any other reads)
    app.router.on_shutdown.append(jobs.shutdown)  # (queued jobs dropped; a running one finishes in its thread)

    @app.exception_handler(StarletteHTTPException)
    async def http_errors(request: Request, e: StarletteHTTPException) -> Any:  # (no such route, method)
        return _error(e.status_code, "NotFound" if e.status_code == 404 else "HTTPError",
                      f"{request.method} {request.url.path}: {e.detail}")

    @app.get("/", response_class=HTMLResponse)
    async def design_page() -> Response:
        from pkm.serve.page import PAGE

        return HTMLResponse(PAGE)

    @app.get("/health")
    async def health() -> dict:
        return {"status": "ok", "version": __version__}

    @app.get("/models")
    async def models(request: Request) -> Response:
        return answer(request, {"models": [vars(e) for e in store.entries()]})

    @app.post("/models", status_code=201)
    async def upload(request: Request) -> Response:
        form = await request.form(max_files=16, max_fields=16)
        files = {}
        for _, value in form.multi_items():
            if not isinstance(value, str):
                files[str(value.filename or "")] = await value.read()
        entry = await limiter.run(lambda: store.add(files))
        return answer(request, vars(entry), 201)

    @app.get("/models/{model}")
    async def model(request: Request, model: str) -> Response:
        entry = store.entry(model)
        mech = await limiter.run(lambda: store.mechanism(model))
        return answer(request, {**vars(entry), **describe(mech)})

    @app.get("/models/{model}/parameters")
    async def parameters(request: Request, model: str) -> Response:
        from pkm.cli.parsing import param_info

        entry = store.entry(model)
        name = model if entry.kind == "registered" else model.split("@")[0] if entry.kind == "variant" else None
        infos = [] if name is None else [
            {"name": p.name, "default": p.default, "units": list(p.units), "description": p.description}
            for p in param_info(name).values()]
        return answer(request, {"model": model, "registered": name, "parameters": infos})

    @app.post("/models/{model}/variants", status_code=201)
    async def variant(request: Request, model: str) -> Response:
        body = await body_of(request)
        entry = await limiter.run(lambda: store.variant(model, body.get("params", {})))
        return answer(request, vars(entry), 201)

    @app.get("/models/{model}/files")
    async def files(request: Request, model: str) -> Response:
        return answer(request, {"files": {n: d.decode() for n, d in store.files(model).items()}})

    @app.delete("/models/{model}", status_code=204, response_class=Response, response_model=None)
    async def delete(model: str) -> Response:
        store.delete(model)
        return Response(status_code=204)

    @app.get("/models/{model}/preview", response_class=HTMLResponse)
    async def preview(model: str) -> Response:
        from pkm.viz.page import snapshot_html

        mech = store.mechanism(model)
        return HTMLResponse(await limiter.run(lambda: snapshot_html(mech)))

    @app.post("/models/{model}/{query}")
    async def run_query(request: Request, model: str, query: str) -> Response:
        if query not in QUERIES:
            raise UnknownNameError("query", query, sorted(QUERIES))
        body = await body_of(request)
        mech = store.mechanism(model)

        def compute() -> dict:
            kernels = store.kernels(model)
            t0 = time.perf_counter()
            out = QUERIES[query](mech, body, kernels)
            out["compute_s"] = time.perf_counter() - t0
            return out

        return answer(request, await limiter.run(compute, compute_limit))

    @app.post("/models/{model}/jobs/{kind}", status_code=202)
    async def start_job(request: Request, model: str, kind: str) -> Response:
        body = await body_of(request)
        mech = await limiter.run(lambda: store.mechanism(model))
        return answer(request, jobs.submit(kind, model, mech, body).summary(), 202)

    @app.get("/jobs")
    async def list_jobs(request: Request) -> Response:
        return answer(request, {"jobs": [j.summary() for j in jobs.list()]})

    @app.get("/jobs/{job_id}")
    async def job_state(request: Request, job_id: str) -> Response:
        return answer(request, jobs.get(job_id).summary())

    @app.get("/jobs/{job_id}/result")
    async def job_result(request: Request, job_id: str, format: str = "json") -> Response:
        from pkm.serve.jobs import parquet

        job = jobs.get(job_id)
        if job.state != "done" or job.result is None or job.rows is None:
            return _error(409, "NotReady", f"job {job_id} is {job.state}", job.summary())
        if format == "parquet":
            rows = job.rows
            return Response(await limiter.run(lambda: parquet(rows)), media_type="application/vnd.apache.parquet")
        if format != "json":
            return _error(422, "InvalidInputError", "format: json or parquet", format)
        return answer(request, {**job.summary(), "result": job.result})

    @app.delete("/jobs/{job_id}")
    async def cancel_job(request: Request, job_id: str) -> Response:
        return answer(request, jobs.cancel(job_id).summary())

    @app.websocket("/models/{model}/stream")
    async def stream(ws: WebSocket, model: str) -> None:
        from pkm.serve.stream import Stream

        if token is not None and ws.headers.get("authorization") != f"Bearer {token}":
            await ws.close(code=4401)
            return
        await ws.accept()
        try:
            mech = store.mechanism(model)
            state = Stream(mech, kernels=await limiter.run(lambda: store.kernels(model)))
        except PkmError as e:
            await ws.send_bytes(pack({"error": type(e).__name__, "message": str(e)}))
            await ws.close(code=4404)
            return
        try:
            while True:
                message = await ws.receive()
                if message.get("type") == "websocket.disconnect":
                    break
                raw = message.get("bytes")
                binary = raw is not None
                try:
                    sample = unpack(raw) if raw is not None else json.loads(message.get("text") or "")
                    out = state.step(sample)
                except PkmError as e:
                    out = {"error": type(e).__name__, "message": str(e)}
                except Exception as e:  # (a malformed message is answered, the stream goes on)
                    out = {"error": "BadMessage", "message": f"{type(e).__name__}: {str(e)[:200]}"}
                if binary:
                    await ws.send_bytes(pack(out))
                else:
                    await ws.send_json(jsonable(out))
        except WebSocketDisconnect:
            pass

    return app


class _BadBody(Exception):
    pass


def serve(host: str = "127.0.0.1", port: int = 8000, *, store: str | None = None, workers: int = 2,
          token: str | None = None, queue: int = 64, max_body: int = 32 * 2**20, compute_limit: float = 60.0) -> None:
    """Run the service until SIGINT or SIGTERM (in-flight requests finish first)."""
    from pkm._optional import require

    require("serve", "pkm serve")
    import uvicorn

    app = create_app(Store(store), token=token, workers=workers, queue=queue, max_body=max_body,
                     compute_limit=compute_limit)
    # uvicorn drains on SIGTERM, then raises the signal again with the handler it found: a quiet one here, so that a
    # drained stop exits 0
    signal.signal(signal.SIGTERM, lambda signum, frame: None)
    uvicorn.run(app, host=host, port=port, log_level="warning", timeout_graceful_shutdown=30)


__all__ = ["Limiter", "SizeLimit", "create_app", "serve"]
