"""The HTTP and WebSocket service (``pkm serve``): FastAPI on uvicorn (the ``serve`` extra).

Why FastAPI: it is Starlette (the ASGI toolkit: routing, WebSockets, multipart) plus the OpenAPI schema
(``/openapi.json``) and its browsable docs (``/docs``) generated from the routes, which the issue asks for; uvicorn
is its maintained server (graceful shutdown on SIGTERM: in-flight requests finish, new ones are refused).

The schema is a contract (:mod:`pkm.serve.schemas`): every operation has an ``operationId``, a request model and an
answer model whose fields carry their units and an example, so that a client can be generated from it (CI does:
``tools/generated_client.py``). Endpoints (see ``/docs``): ``GET /health``; ``GET /models``; ``POST /models`` (an
upload: multipart files); ``GET /models/{model}`` (sizes, names, units); ``GET /models/{model}/files``;
``DELETE /models/{model}``; ``GET /models/{model}/parameters`` and ``POST /models/{model}/variants`` (a registered
mechanism with other design parameters); ``GET /models/{model}/preview`` (the self-contained 3-D page); ``GET /``
(the design page, :mod:`pkm.serve.page`); one operation per query of :data:`pkm.serve.queries.QUERIES`:
``POST /models/{model}/fk``, ``/ik``, ``/jacobians``, ``/diagnose``, ``/velocities``, ``/dynamics``, ``/capability``,
``/scene`` (one sample or a batch; an unknown query is 404 listing them); one per job kind (every assembly or working
mode, a workspace map, a design sweep: :mod:`pkm.serve.jobs`) at ``POST /models/{model}/jobs/{kind}``,
``GET /jobs/{id}`` and its ``/result``, ``DELETE /jobs/{id}``; ``WS /models/{model}/stream`` (actuator samples in,
the forward kinematics, task rates and efforts out, warm-started along the stream).

Bodies are JSON, or msgpack (``Content-Type: application/msgpack``; numpy arrays as msgpack extension 1: dtype,
shape and raw bytes, no text round trip), decoded by the routes themselves and then checked by their request model
(unknown fields refused; arrays left to pkm's own parsing, so that large batches cost no pydantic walk); answers are
JSON unless ``Accept`` asks for msgpack, a non-finite number ``null`` in JSON. Every answer of a query carries
``compute_s``, the server's time for it.

Reliability: pkm's errors are 4xx answers with their ``error``, ``message`` and ``data`` (422; 404 for an unknown
model, query or job), never a traceback: one sample that fails (unreachable, singular, not converged) is its
error's 422, a batch answers 200 with each sample's status and ``null`` values for the failed ones; a body over
``max_body`` bytes is 413; a bearer token, when set, is required on everything but ``/health`` (401); at most
``workers`` queries compute at once and ``queue`` wait, the next is 429; a query computing longer than
``compute_limit`` seconds is answered 503.
"""

# (no ``from __future__ import annotations`` here: FastAPI reads the routes' annotations, whose types are imported
# inside create_app, when pkm-robotics[serve] is known to be installed)
import asyncio
import json
import math
import signal
import time
from collections.abc import Callable
from typing import Any, Literal

import numpy as np

from pkm.errors import PkmError, UnknownNameError
from pkm.report import jsonable
from pkm.serve.store import Store
from pkm.serve.wire import MSGPACK, ND_LAYOUT, pack, unpack


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
    from typing import Annotated

    from fastapi import FastAPI, Path, Request, WebSocket, WebSocketDisconnect
    from fastapi.exceptions import RequestValidationError
    from fastapi.responses import HTMLResponse, JSONResponse, Response
    from pydantic import BaseModel, ValidationError
    from starlette.exceptions import HTTPException as StarletteHTTPException

    from pkm import MECHANISMS, __version__
    from pkm.serve import schemas
    from pkm.serve.jobs import KINDS, JobManager
    from pkm.serve.offline import add_offline_docs
    from pkm.serve.queries import QUERIES, describe

    store = Store() if store is None else store
    _Invalid = _invalid_class()
    limiter = Limiter(workers, queue)
    jobs = JobManager(job_workers)
    app = FastAPI(title="pkm", version=__version__,
                  description="Kinematics and dynamics of closed-loop mechanisms: models, queries, streams. Bodies "
                              f"and answers are JSON, or msgpack (content-type, accept: {MSGPACK}). {ND_LAYOUT}",
                  docs_url=None, redoc_url=None)
    add_offline_docs(app)  # (/docs and /redoc from local files, not FastAPI's CDN: pkm.serve.offline)

    def answer(request: Request, payload: Any, status: int = 200) -> Response:
        if MSGPACK in request.headers.get("accept", ""):
            return Response(pack(payload), media_type=MSGPACK, status_code=status)
        return JSONResponse(_plain(payload), status_code=status)

    def validated(model: type[BaseModel], body: dict) -> dict:
        """``body`` checked against ``model`` (unknown fields, types; arrays are left to pkm's parsing): its fields
        (None where not given), or the 422 of :func:`invalid`."""
        try:
            return dict(model.model_validate(body))
        except ValidationError as e:
            raise _Invalid(e.errors(include_url=False, include_context=False, include_input=False),
                           list(model.model_fields)) from None

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
        errors = [{"loc": [str(x) for x in d.get("loc", ())], "msg": str(d.get("msg", "")), "type": str(d.get("type"))}
                  for d in e.errors()]
        said = "; ".join(_said(d, getattr(e, "fields", None)) for d in errors)
        return _error(422, "InvalidRequest", f"the request does not match the endpoint: {said}", errors)

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

    registered = sorted(MECHANISMS)
    Model = Annotated[str, Path(description="The model's id: a registered mechanism (" + ", ".join(registered)
                                + "), an upload's id or a variant's; GET /models lists them all.",
                                examples=registered)]
    errors: dict[int | str, dict[str, Any]] = {
        status: {"model": schemas.ErrorAnswer, "description": what} for status, what in (
        (404, "No such model (or job)"),
        (422, "Refused input (unknown field, wrong type or shape, bad unit), or one sample that failed: pkm's error"),
        (429, "Too many requests waiting"), (503, "The computation ran past the service's compute-time limit"))}

    def body_schema(model: type[BaseModel]) -> dict:
        """The OpenAPI request body of an operation that decodes its body itself (JSON or msgpack)."""
        ref = {"schema": {"$ref": f"#/components/schemas/{model.__name__}"}}
        return {"requestBody": {"required": True, "content": {"application/json": ref, MSGPACK: ref}}}

    @app.get("/health", response_model=schemas.Health, tags=["service"], operation_id="health")
    async def health() -> dict:
        return {"status": "ok", "version": __version__}

    @app.get("/models", response_model=schemas.ModelList, tags=["models"], operation_id="list_models")
    async def models(request: Request) -> Response:
        return answer(request, {"models": [vars(e) for e in store.entries()]})

    @app.post("/models", status_code=201, response_model=schemas.ModelEntry, tags=["models"], operation_id="upload",
              responses={422: errors[422]}, openapi_extra={"requestBody": {"required": True, "content": {
                  "multipart/form-data": {"schema": {"$ref": "#/components/schemas/Upload"}}}}})
    async def upload(request: Request) -> Response:
        form = await request.form(max_files=16, max_fields=16)
        files, folder = {}, None
        for key, value in form.multi_items():
            if not isinstance(value, str):
                files[str(value.filename or "")] = await value.read()
            elif key == "folder":
                folder = value
        entry = await limiter.run(lambda: store.add(files, folder=folder))
        return answer(request, vars(entry), 201)

    @app.get("/models/{model}", response_model=schemas.ModelDescription, tags=["models"], operation_id="describe_model",
             responses={404: errors[404]})
    async def model(request: Request, model: Model) -> Response:
        entry = store.entry(model)
        mech = await limiter.run(lambda: store.mechanism(model))
        return answer(request, {**vars(entry), **describe(mech)})

    @app.get("/models/{model}/parameters", response_model=schemas.Parameters, tags=["models"],
             operation_id="parameters", responses={404: errors[404]})
    async def parameters(request: Request, model: Model) -> Response:
        from pkm.cli.parsing import param_info

        entry = store.entry(model)
        name = model if entry.kind == "registered" else model.split("@")[0] if entry.kind == "variant" else None
        infos = [] if name is None else [
            {"name": p.name, "default": p.default, "units": list(p.units), "description": p.description}
            for p in param_info(name).values()]
        return answer(request, {"model": model, "registered": name, "parameters": infos})

    @app.post("/models/{model}/variants", status_code=201, response_model=schemas.ModelEntry, tags=["models"],
              operation_id="variant", responses={404: errors[404], 422: errors[422]},
              openapi_extra=body_schema(schemas.VariantRequest))
    async def variant(request: Request, model: Model) -> Response:
        body = validated(schemas.VariantRequest, await body_of(request))
        entry = await limiter.run(lambda: store.variant(model, body["params"]))
        return answer(request, vars(entry), 201)

    @app.get("/models/{model}/files", response_model=schemas.FilesAnswer, tags=["models"], operation_id="model_files",
             responses={404: errors[404]})
    async def files(request: Request, model: Model) -> Response:
        return answer(request, {"files": {n: d.decode() for n, d in store.files(model).items()}})

    @app.delete("/models/{model}", status_code=204, response_class=Response, response_model=None, tags=["models"],
                operation_id="delete_model", responses={404: errors[404]})
    async def delete(model: Model) -> Response:
        store.delete(model)
        return Response(status_code=204)

    @app.get("/models/{model}/preview", response_class=HTMLResponse, tags=["models"], operation_id="preview",
             responses={404: errors[404]})
    async def preview(model: Model) -> Response:
        from pkm.viz.page import snapshot_html

        mech = store.mechanism(model)
        return HTMLResponse(await limiter.run(lambda: snapshot_html(mech)))

    def query_operation(name: str) -> Callable:
        request_model = schemas.QUERY_MODELS[name][0]

        async def run_query(request: Request, model: Model) -> Response:
            body = validated(request_model, await body_of(request))
            mech = store.mechanism(model)

            def compute() -> dict:
                kernels = store.kernels(model)
                t0 = time.perf_counter()
                out = QUERIES[name](mech, body, kernels)
                out["compute_s"] = time.perf_counter() - t0
                return out

            return answer(request, await limiter.run(compute, compute_limit))

        return run_query

    for name in QUERIES:  # (one typed operation per query: its request and answer schemas, examples, units)
        request_model, answer_model, summary = schemas.QUERY_MODELS[name]
        app.add_api_route(f"/models/{{model}}/{name}", query_operation(name), methods=["POST"], operation_id=name,
                          summary=summary, description=QUERIES[name].__doc__, tags=["queries"],
                          response_model=answer_model, responses=errors, openapi_extra=body_schema(request_model))

    @app.post("/models/{model}/{query}", include_in_schema=False)
    async def unknown_query(model: str, query: str) -> Response:  # (an unknown query: 404 naming the valid ones)
        raise UnknownNameError("query", query, sorted(QUERIES))

    def job_operation(kind: str) -> Callable:
        request_model = schemas.JOB_MODELS[kind][0]

        async def start_job(request: Request, model: Model) -> Response:
            body = validated(request_model, await body_of(request))
            body = {k: v for k, v in body.items() if v is not None}
            mech = await limiter.run(lambda: store.mechanism(model))
            return answer(request, jobs.submit(kind, model, mech, body).summary(), 202)

        return start_job

    for kind in KINDS:
        request_model, summary = schemas.JOB_MODELS[kind]
        app.add_api_route(f"/models/{{model}}/jobs/{kind}", job_operation(kind), methods=["POST"], status_code=202,
                          operation_id=f"job_{kind}", summary=summary, description=KINDS[kind].__doc__, tags=["jobs"],
                          response_model=schemas.JobState, responses=errors, openapi_extra=body_schema(request_model))

    @app.post("/models/{model}/jobs/{kind}", include_in_schema=False)
    async def unknown_job(model: str, kind: str) -> Response:
        raise UnknownNameError("job kind", kind, sorted(KINDS))

    @app.get("/jobs", response_model=schemas.JobList, tags=["jobs"], operation_id="list_jobs")
    async def list_jobs(request: Request) -> Response:
        return answer(request, {"jobs": [j.summary() for j in jobs.list()]})

    @app.get("/jobs/{job_id}", response_model=schemas.JobState, tags=["jobs"], operation_id="job_state",
             responses={404: errors[404]})
    async def job_state(request: Request, job_id: str) -> Response:
        return answer(request, jobs.get(job_id).summary())

    @app.get("/jobs/{job_id}/result", response_model=schemas.JobResult, tags=["jobs"], operation_id="job_result",
             responses={404: errors[404], 409: {"model": schemas.ErrorAnswer, "description": "Not finished yet"},
                        410: {"model": schemas.ErrorAnswer, "description": "Cancelled: there will be no result"},
                        422: {"model": schemas.ErrorAnswer, "description": "Failed: the job's own error"},
                        200: {"content": {"application/vnd.apache.parquet": {}}}})
    async def job_result(request: Request, job_id: str, format: Literal["json", "parquet"] = "json") -> Response:
        from pkm.serve.jobs import parquet

        job = jobs.get(job_id)
        if job.state == "failed" and job.error is not None:  # (its own error, as the query would have answered it)
            return _error(500 if job.defect else 422, job.error["error"], job.error["message"], job.summary())
        if job.state == "cancelled":
            return _error(410, "Cancelled", f"job {job_id} was cancelled: it has no result", job.summary())
        if job.state != "done" or job.result is None or job.rows is None:
            return _error(409, "NotReady", f"job {job_id} is {job.state}", job.summary())
        if format == "parquet":
            rows = job.rows
            return Response(await limiter.run(lambda: parquet(rows)), media_type="application/vnd.apache.parquet")
        return answer(request, {**job.summary(), "result": job.result})

    @app.delete("/jobs/{job_id}", response_model=schemas.JobState, tags=["jobs"], operation_id="cancel_job",
                responses={404: errors[404]})
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
                    await ws.send_json(_plain(out))  # (non-finite as null, as every answer)
        except WebSocketDisconnect:
            pass

    default_openapi = app.openapi

    def openapi() -> dict[str, Any]:  # (the request models' schemas: the bodies are decoded by the routes themselves)
        if app.openapi_schema is None:
            schema = default_openapi()
            components = schema.setdefault("components", {}).setdefault("schemas", {})
            components.update(schemas.request_schemas())
            components["Upload"] = {"type": "object", "required": ["files"], "properties": {"files": {
                "type": "array", "items": {"type": "string", "format": "binary"},
                "description": "A model's files (URDF, MJCF, SDF, YAML, a closures TOML...) or one zip or tar of them"},
                "folder": {"type": "string", "description": "The folder the files are in: it names a Gepetto pair "
                           "whose URDF is robot.urdf, as pkm.load names it (default: an archive's folder, or its "
                           "name)"}}}
            if token is not None:  # (the bearer scheme: Swagger UI's Authorize button then adds the header)
                schema["components"]["securitySchemes"] = {"bearer": {
                    "type": "http", "scheme": "bearer", "description": "the token `pkm serve --token` was given"}}
                for route, operations in schema.get("paths", {}).items():
                    for operation in operations.values():
                        operation["security"] = [] if route in ("/", "/health") else [{"bearer": []}]
        return app.openapi_schema or {}

    app.openapi = openapi  # type: ignore[method-assign]
    return app


class _BadBody(Exception):
    pass


def _invalid_class() -> type:
    from fastapi.exceptions import RequestValidationError

    class _Invalid(RequestValidationError):
        """A body refused by its request model: the errors, and the model's fields (for the message)."""

        def __init__(self, errors: Any, fields: list[str]):
            super().__init__(errors)
            self.fields = fields

    return _Invalid


def _said(error: dict, fields: list[str] | None) -> str:
    """One refused field in words: an unknown one named with the fields there are."""
    loc = [x for x in error["loc"] if x != "body"]
    where = ".".join(loc) or "the body"
    if error["type"] == "extra_forbidden":
        known = f" (the fields: {', '.join(fields)})" if fields else ""
        return f"unknown field {where!r}{known}"
    return f"{where}: {error['msg']}"


def _plain(x: Any) -> Any:
    """``x`` as JSON values: numpy arrays as lists, non-finite numbers as None (``null``: never NaN, never a string
    for a number)."""
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, np.ndarray):
        if x.ndim == 0:
            return _plain(x.item())
        if x.dtype.kind in "biu" or (x.dtype.kind == "f" and np.isfinite(x).all()):
            return x.tolist()
        return [_plain(v) for v in x]
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


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
