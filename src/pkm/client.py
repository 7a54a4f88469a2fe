"""A Python client of ``pkm serve``: the library's questions asked of a service (the ``serve`` extra).

``Client(url)`` speaks msgpack (numpy arrays travel as raw bytes) and raises the service's errors as
:class:`ServiceError` carrying the status, the error's name, its message and data::

    from pkm.client import Client
    c = Client("http://127.0.0.1:8000")
    c.models()                                   # registered and uploaded
    model = c.upload(["ankle.xml", "ankle.closures.toml"])["id"]
    r = c.fk(model, qa=[[0.1, -0.1], [0.12, -0.1]])  # a batch: q, y, residual, status per sample
    with c.stream("delta") as s:                 # forward kinematics, rates, efforts per sample
        s.send(qa=[0.1, 0.2, 0.3], qd=[0, 0, 0], qdd=[1, 0, 0])
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from pkm.errors import PkmError


class ServiceError(PkmError):
    """An answer of the service that is not a success: ``status`` (HTTP), ``kind`` (the error's name), ``message``,
    ``data``."""

    def __init__(self, status: int, kind: str, message: str, data: Any = None):
        self.status, self.kind, self.message, self.data = status, kind, message, data
        super().__init__(f"{status} {kind}: {message}")


class Client:
    """The service at ``url`` (see the module doc); ``token``: its bearer token, if it asks one."""

    def __init__(self, url: str = "http://127.0.0.1:8000", *, token: str | None = None, timeout: float = 120.0):
        import httpx

        from pkm._optional import require

        require("serve", "pkm.client", ["httpx", "msgpack"])
        self.url = url.rstrip("/")
        self.token = token
        headers = {"accept": "application/msgpack"}
        if token:
            headers["authorization"] = f"Bearer {token}"
        self._http = httpx.Client(base_url=self.url, headers=headers, timeout=timeout)

    def close(self) -> None:
        self._http.close()

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _answer(self, response: Any) -> Any:
        from pkm.serve.wire import MSGPACK, unpack

        body = unpack(response.content) if response.headers.get("content-type", "").startswith(MSGPACK) \
            else (response.json() if response.content else None)
        if response.status_code >= 400:
            body = body if isinstance(body, dict) else {}
            raise ServiceError(response.status_code, str(body.get("error", "Error")), str(body.get("message", "")),
                               body.get("data"))
        return body

    def health(self) -> dict:
        return self._answer(self._http.get("/health"))

    def models(self) -> list[dict]:
        """Every model: ``id``, ``kind`` (registered, uploaded), ``name``, ``files``."""
        return self._answer(self._http.get("/models"))["models"]

    def upload(self, files: Iterable[str | Path] | Mapping[str, bytes], folder: str | None = None) -> dict:
        """Upload a model's files (paths, or ``{name: bytes}``); returns its entry (``id``...). ``folder``: the name
        of the folder they are in, which names a Gepetto ``robot.urdf`` as :func:`pkm.load` does (default: the
        paths' folder, where they share one)."""
        if isinstance(files, Mapping):
            items = list(files.items())
        else:
            paths = [Path(p) for p in files]
            items = [(p.name, p.read_bytes()) for p in paths]
            parents = {p.resolve().parent.name for p in paths}
            folder = parents.pop() if folder is None and len(parents) == 1 else folder
        data = {} if folder is None else {"folder": folder}
        return self._answer(self._http.post("/models", files=[("files", (n, d)) for n, d in items], data=data))

    def model(self, model: str) -> dict:
        """Sizes, names and units of ``model``."""
        return self._answer(self._http.get(f"/models/{model}"))

    def delete(self, model: str) -> None:
        self._answer(self._http.delete(f"/models/{model}"))

    def query(self, model: str, query: str, **body: Any) -> dict:
        """``POST /models/{model}/{query}`` with ``body`` (arrays as numpy arrays or lists; None values left out).

        A batch (every array a list of samples) answers per sample: ``status`` (``"ok"``, ``"outside_limits"``: the
        joints outside the model's position limits in ``outside_limits``, or ``"failed"``), ``failures``, None for a
        failed sample's values; one sample that fails raises :class:`ServiceError` (422, pkm's error's name and
        data)."""
        from pkm.serve.wire import MSGPACK, pack

        body = {k: v for k, v in body.items() if v is not None}
        response = self._http.post(f"/models/{model}/{query}", content=pack(body),
                                   headers={"content-type": MSGPACK})
        return self._answer(response)

    def fk(self, model: str, qa: Any, seed: Any = None) -> dict:
        """The forward kinematics at actuated values ``qa`` (``q``, ``y``, ``residual``, ``iterations``)."""
        return self.query(model, "fk", qa=qa, seed=seed)

    def ik(self, model: str, y: Any, seed: Any = None, branch: str | None = None) -> dict:
        """The inverse kinematics at task values ``y`` (``q``, ``qa``, ``residual``, ``iterations``)."""
        return self.query(model, "ik", y=y, seed=seed, branch=branch)

    def jacobians(self, model: str, q: Any = None, *, qa: Any = None, seed: Any = None) -> dict:
        """``J`` and ``K`` at configurations ``q``, or at actuated values ``qa`` (the loops closed from ``seed``)."""
        return self.query(model, "jacobians", q=q, qa=qa, seed=seed)

    def diagnose(self, model: str, q: Any = None, *, qa: Any = None, seed: Any = None) -> dict:
        """The distances to the direct and inverse singularities at ``q``, or at actuated values ``qa``."""
        return self.query(model, "diagnose", q=q, qa=qa, seed=seed)

    def velocities(self, model: str, q: Any = None, qd: Any = None, qdd: Any = None, *, qa: Any = None,
                   seed: Any = None) -> dict:
        """Joint and task rates ``v``, ``yd`` at actuated rates ``qd`` (with ``qdd``: ``a``, ``ydd``) at ``q``, or at
        actuated values ``qa``."""
        return self.query(model, "velocities", q=q, qa=qa, qd=qd, qdd=qdd, seed=seed)

    def dynamics(self, model: str, q: Any = None, qd: Any = None, qdd: Any = None, *, qa: Any = None,
                 seed: Any = None) -> dict:
        """``M``, ``h``, ``g`` (and ``tau`` with ``qdd``) at ``q``, or at actuated values ``qa``."""
        return self.query(model, "dynamics", q=q, qa=qa, qd=qd, qdd=qdd, seed=seed)

    def capability(self, model: str, q: Any = None, kind: str = "wrench", *, qa: Any = None, seed: Any = None) -> dict:
        """The ``kind`` capability (``wrench``, ``twist``, ``acceleration``) at ``q``, or at actuated values ``qa``."""
        return self.query(model, "capability", q=q, qa=qa, kind=kind, seed=seed)

    def job(self, model: str, kind: str, **body: Any) -> dict:
        """Start a job (``assembly_modes`` with ``qa``, ``working_modes`` with ``y``, ``map`` with ``axes``...);
        returns its state (``id``...)."""
        from pkm.serve.wire import MSGPACK, pack

        return self._answer(self._http.post(f"/models/{model}/jobs/{kind}", content=pack(body),
                                            headers={"content-type": MSGPACK}))

    def job_state(self, job_id: str) -> dict:
        return self._answer(self._http.get(f"/jobs/{job_id}"))

    def result(self, job_id: str, *, wait: float = 600.0) -> dict:
        """A job's result, waiting up to ``wait`` seconds for it to finish: the service's :class:`ServiceError` if
        it failed (422 with the job's own error, 500 on a defect), was cancelled (410) or is still running (409)."""
        import time

        deadline = time.monotonic() + wait
        while self.job_state(job_id)["state"] in ("queued", "running") and time.monotonic() < deadline:
            time.sleep(0.05)
        return self._answer(self._http.get(f"/jobs/{job_id}/result"))["result"]

    def cancel(self, job_id: str) -> dict:
        return self._answer(self._http.delete(f"/jobs/{job_id}"))

    @contextmanager
    def stream(self, model: str) -> Iterator[Stream]:
        """A WebSocket stream over ``model`` (:class:`Stream`)."""
        from websockets.sync.client import connect

        ws_url = "ws" + self.url[4:] + f"/models/{model}/stream"
        headers = {"authorization": f"Bearer {self.token}"} if self.token else None
        with connect(ws_url, additional_headers=headers, max_size=2**24) as ws:
            yield Stream(ws)


class Stream:
    """An open stream: :meth:`send` one sample and get its answer (``q``, ``y``, ``yd``, ``tau``...)."""

    def __init__(self, ws: Any):
        self.ws = ws

    def send(self, **sample: Any) -> dict:
        from pkm.serve.wire import pack, unpack

        self.ws.send(pack(sample))
        out = unpack(self.ws.recv())
        if isinstance(out, dict) and "error" in out:
            raise ServiceError(422, str(out["error"]), str(out.get("message", "")))
        return out


__all__ = ["Client", "ServiceError", "Stream"]
