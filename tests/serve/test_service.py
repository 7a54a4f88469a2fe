"""``pkm serve`` through a real uvicorn on a free local port (tests/serve/conftest.py): every endpoint through the
client (msgpack) and over raw HTTP (JSON) and WebSocket, answers equal to the library's in-process calls, and bad
requests answered 4xx with their message (never a 500, never a traceback)."""

from __future__ import annotations

import asyncio
import json
from pathlib import Path

import numpy as np
import pytest

import pkm
from tests import http
from tests.serve.conftest import TOKEN

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
AUTH = {"authorization": f"Bearer {TOKEN}"}


@pytest.fixture(scope="module")
def delta():
    return pkm.load("delta")


def _path(mech, n=5):
    return mech.actuated_q(mech.q_reference) + 0.02 * np.arange(1, n + 1)[:, None] * np.array([1.0, -0.5, 0.3])


def test_health_is_open_and_everything_else_needs_the_token(service):
    assert http.get(service.url + "/health").json()["status"] == "ok"
    for path in ("/models", "/models/delta", "/openapi.json"):
        r = http.get(service.url + path)
        assert r.status_code == 401 and r.json()["error"] == "Unauthorized"
    assert http.get(service.url + "/models", headers={"authorization": "Bearer wrong"}).status_code == 401
    schema = http.get(service.url + "/openapi.json", headers=AUTH).json()
    assert {"/models", "/models/{model}/fk", "/models/{model}/preview"} <= set(schema["paths"])


def test_the_queries_answer_what_the_library_does(client, delta):
    models = {m["id"]: m for m in client.models()}
    assert {"delta", "rrr3", "prs3", "hexapod", "gough_stewart"} <= set(models)
    about = client.model("delta")
    assert about["na"] == 3 and about["task_units"] == {"x": "m", "y": "m", "z": "m"}
    qa = _path(delta)
    fk = client.fk("delta", qa)
    q, previous = [], delta.q_reference
    for a in qa:  # each sample from the previous solution, as the service solves a batch
        previous = pkm.close_loops(delta, a, previous).q
        q.append(previous)
    assert fk["status"] == ["ok"] * 5 and np.abs(fk["q"] - np.array(q)).max() <= 1e-12
    assert fk["residual"].max() <= 1e-10 and fk["compute_s"] > 0 and fk["units"]["y"] == ["m", "m", "m"]
    ik = client.ik("delta", fk["y"])
    assert np.abs(ik["qa"] - qa).max() <= 1e-9
    jac = client.jacobians("delta", fk["q"][:2])
    assert np.abs(jac["J"][1] - pkm.forward_jacobian(delta, fk["q"][1])).max() <= 1e-12
    assert np.abs(jac["K"][0] - pkm.inverse_jacobian(delta, fk["q"][0])).max() <= 1e-12
    diag = client.diagnose("delta", fk["q"][0])
    assert diag["direct_distance"][0] == pytest.approx(pkm.diagnose(delta, fk["q"][0]).direct_distance, rel=1e-12)
    qd, qdd = np.array([0.1, -0.2, 0.3]), np.array([1.0, 0.5, -0.5])
    vel = client.query("delta", "velocities", q=fk["q"], qd=qd, qdd=qdd)  # (one qd, qdd for every sample)
    v2 = pkm.velocities(delta, fk["q"][2], qd)
    a2 = pkm.accelerations(delta, fk["q"][2], v2, qdd)
    assert np.abs(vel["v"][2] - v2).max() <= 1e-12 and np.abs(vel["a"][2] - a2).max() <= 1e-12
    assert np.abs(vel["ydd"][2] - pkm.task_acceleration(delta, fk["q"][2], v2, a2)).max() <= 1e-12
    dyn = client.dynamics("delta", fk["q"][:2], qd, qdd)
    model = pkm.actuator_model(delta, fk["q"][1], qd)
    assert np.abs(dyn["tau"][1] - (model.M @ qdd + model.h)).max() <= 1e-12 and dyn["units"]["tau"] == ["N m"] * 3
    cap = client.capability("delta", fk["q"][0], "twist")
    c = pkm.capability(delta, fk["q"][0], "twist")
    assert np.allclose(cap["along"][0], np.array(list(c.along.values())), rtol=1e-12) and cap["axes"] == ["x", "y", "z"]
    raw = http.post(client.url + "/models/delta/fk", json={"qa": qa.tolist()}, headers=AUTH).json()  # JSON
    assert np.abs(np.array(raw["q"]) - fk["q"]).max() == 0.0


def test_a_failing_sample_does_not_fail_the_batch_but_fails_alone(client, service, delta):
    """A batch keeps its shape: null (None) for the failed sample's values, its status and error; the same sample
    given alone is a 422 with pkm's error JSON (never a 200 with a failure inside)."""
    from pkm.client import ServiceError

    y = [[0.0, 0.0, -0.35], [0.0, 0.0, -3.0]]  # (the second 3 m down: out of reach)
    out = client.ik("delta", y)
    assert out["status"] == ["ok", "failed"] and [f["sample"] for f in out["failures"]] == [1]
    assert out["failures"][0]["error"] in ("ConvergenceError", "UnreachableError")
    assert out["q"][1] is None and out["iterations"][1] is None and np.isfinite(out["q"][0]).all()
    assert isinstance(out["iterations"][0], int)
    raw = http.post(service.url + "/models/delta/ik", json={"y": y}, headers=AUTH)
    assert raw.status_code == 200 and raw.json()["q"][1] is None and "nan" not in raw.text.lower()
    with pytest.raises(ServiceError) as e:
        client.ik("delta", y[1])
    assert e.value.status == 422 and e.value.kind == out["failures"][0]["error"] and e.value.data["leg"] >= 1
    with pytest.raises(ServiceError) as e:  # (a configuration asked by qa whose loops do not close: that sample's)
        client.dynamics("prs3", qa=[0.6, -0.4, 0.6], qdd=[1.0, 0.0, 0.0])
    assert e.value.status == 422


def test_uploads_are_content_addressed_kept_and_deleted(client, service, tmp_path):
    from pkm.client import ServiceError
    from pkm.serve.store import Store

    files = [EXAMPLES / "humanoid_ankle" / "ankle.xml", EXAMPLES / "humanoid_ankle" / "ankle.closures.toml"]
    entry = client.upload(files)
    assert client.upload(files)["id"] == entry["id"] and entry["name"] == "humanoid_ankle"
    assert entry["id"] in {m["id"] for m in client.models()}
    assert set(client._answer(client._http.get(f"/models/{entry['id']}/files"))["files"]) == {f.name for f in files}
    out = client.fk(entry["id"], [0.1, -0.1])
    mech = pkm.load(files[1])
    assert np.abs(out["y"][0] - pkm.TaskMap.of(mech).value(pkm.close_loops(mech, [0.1, -0.1]).q)).max() <= 1e-12
    page = http.get(f"{client.url}/models/{entry['id']}/preview", headers=AUTH)
    assert page.status_code == 200 and "<html" in page.text.lower()
    again = Store(service_store(service))  # (a new service on the same folder serves it again)
    assert entry["id"] in {e.id for e in again.entries()}
    client.delete(entry["id"])
    with pytest.raises(ServiceError) as e:
        client.fk(entry["id"], [0.1, -0.1])
    assert e.value.status == 404


def test_an_archive_is_its_files(client, service):
    """A zip (or tar) of a model's files is the same upload as the files (the same id); folders in it are dropped,
    a link refused."""
    import io
    import tarfile
    import zipfile

    files = [EXAMPLES / "humanoid_ankle" / "ankle.xml", EXAMPLES / "humanoid_ankle" / "ankle.closures.toml"]
    plain = client.upload(files)
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for f in files:
            z.writestr(f"../../deep/{f.name}", f.read_bytes())  # (a zip-slip path: only the base name is kept)
    assert client.upload({"ankle.zip": buf.getvalue()})["id"] == plain["id"]
    tar = io.BytesIO()
    with tarfile.open(fileobj=tar, mode="w:gz") as t:
        link = tarfile.TarInfo("ankle.xml")
        link.type, link.linkname = tarfile.SYMTYPE, "/etc/passwd"
        t.addfile(link)
    r = http.post(service.url + "/models", files=[("files", ("m.tgz", tar.getvalue()))], headers=AUTH)
    assert r.status_code == 422 and "link" in r.json()["message"]


def test_an_uploaded_gepetto_robot_is_named_as_pkm_load_names_it(client, service):
    """Gepetto's battobot is ``battobot_6d/robot.urdf`` + ``robot.yaml``: pkm.load names it ``battobot_6d``, an upload
    named it "robot". Uploaded by path (the client sends the folder), as a zip of the folder, or with ``folder`` stated:
    ``battobot_6d``, one id; kept so by a new service on the same store."""
    import io
    import zipfile

    from pkm.serve.store import Store

    folder = Path(__file__).resolve().parents[2] / "urdf" / "gepetto" / "battobot_6d"
    paths = [folder / "robot.urdf", folder / "robot.yaml"]
    name = pkm.load("gepetto:battobot_6d").name
    entry = client.upload(paths)
    assert name == "battobot_6d" and entry["name"] == name
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for p in paths:
            z.writestr(f"battobot_6d/{p.name}", p.read_bytes())
    assert client.upload({"anything.zip": buf.getvalue()})["id"] == entry["id"]
    assert client.upload({p.name: p.read_bytes() for p in paths}, folder="battobot_6d")["id"] == entry["id"]
    assert {e.id: e.name for e in Store(service_store(service)).entries()}[entry["id"]] == name
    r = http.post(service.url + "/models", files=[("files", (p.name, p.read_bytes())) for p in paths],
                   data={"folder": "../x"}, headers=AUTH)
    assert r.status_code == 422 and "folder" in r.text


def service_store(service) -> Path:
    return service.store_folder


@pytest.mark.parametrize(("files", "status", "says"), [
    ({"../../evil.urdf": b"<robot name='x'/>"}, 422, "plain name"),
    ({"a.urdf": b"\xff\xfe\x00"}, 422, "UTF-8"),
    ({"robot.xml": b"<?xml version='1.0'?><!DOCTYPE lolz [<!ENTITY lol 'lol'><!ENTITY lol2 '&lol;&lol;&lol;'>]>"
                   b"<mujoco><worldbody/></mujoco>"}, 422, ""),
    ({"x.closures.toml": b'format = "pkm.closures/1"\nurdf = "../../etc/passwd"\n'}, 422, ""),
    ({"only.urdf": b"<robot name='r'><link name='a'/></robot>"}, 422, "spec"),
])
def test_bad_uploads_are_refused(service, files, status, says, tmp_path):
    r = http.post(service.url + "/models", files=[("files", (n, d)) for n, d in files.items()], headers=AUTH)
    assert r.status_code == status, r.text
    assert says in r.json()["message"] and "Traceback" not in r.text
    assert not (tmp_path.parent / "evil.urdf").exists()


@pytest.mark.parametrize(("path", "body", "headers", "status"), [
    ("/models/delta/fk", b"{bad json", {}, 400),
    ("/models/delta/fk", b"\xc1\xc1", {"content-type": "application/msgpack"}, 400),
    ("/models/delta/fk", json.dumps({"qa": [1, 2]}).encode(), {}, 422),
    ("/models/delta/fk", json.dumps({"qa": [[1, 2, "x"]]}).encode(), {}, 422),
    ("/models/delta/fk", json.dumps({"qa": [1, 2, float("nan")]}).encode().replace(b"NaN", b"1e999"), {}, 422),
    ("/models/delta/fk", json.dumps([1, 2, 3]).encode(), {}, 400),
    ("/models/delta/teleport", b"{}", {}, 404),
    ("/models/nope/fk", json.dumps({"qa": [1, 2, 3]}).encode(), {}, 404),
    ("/models/delta/capability", json.dumps({"q": [0.0] * 15, "kind": "power"}).encode(), {}, 422),
    ("/models/delta/fk", json.dumps({"qa": [1, 2, 3], "foo": 1}).encode(), {}, 422),
    ("/models/delta/dynamics", json.dumps({"qa": [1, 2, 3], "q": [0.0] * 12}).encode(), {}, 422),
    ("/models/delta/dynamics", json.dumps({"qd": [1, 2, 3]}).encode(), {}, 422),
    ("/models/delta/fk", json.dumps({"qa": ["10deg", "1mm", 0.0]}).encode(), {}, 422),
    ("/models/delta/ik", json.dumps({"y": [0, 0, -0.35], "branch": 3}).encode(), {}, 422),
    ("/models/delta/jobs/map", json.dumps({"axes": {"x": [0, 1, 3]}, "what": 1}).encode(), {}, 422),
    ("/models/delta/variants", json.dumps({"params": {"R": 0.16}, "x": 1}).encode(), {}, 422),
    ("/models/delta/fk", b"x" * (2**20 + 10), {}, 413),
])
def test_bad_requests_are_4xx_with_their_message(service, path, body, headers, status):
    r = http.post(service.url + path, content=body, headers={**AUTH, **headers})
    assert r.status_code == status, r.text
    answer = r.json()
    assert answer["message"] and set(answer) == {"error", "message", "data"} and "Traceback" not in r.text
    assert http.get(service.url + "/health").status_code == 200  # (still answering)


def test_the_stream_warm_starts_and_answers_bad_messages(client, service, delta):
    from websockets.sync.client import connect

    qa = _path(delta, 3)
    with client.stream("delta") as s:
        answers = [s.send(qa=a, qd=[0.1, 0.0, 0.0], qdd=[1.0, 0.0, 0.0]) for a in qa]
    q = pkm.close_loops(delta, qa[0], delta.q_reference).q
    assert np.abs(answers[0]["q"] - q).max() <= 1e-10 and answers[0]["residual"] <= 1e-10
    assert answers[0]["status"] == "ok" and answers[0]["outside_limits"] == []
    model = pkm.actuator_model(delta, answers[2]["q"], np.array([0.1, 0.0, 0.0]))
    assert np.abs(answers[2]["tau"] - (model.M @ np.array([1.0, 0.0, 0.0]) + model.h)).max() <= 1e-12
    url = "ws" + service.url[4:] + "/models/delta/stream"
    with connect(url, additional_headers=AUTH) as ws:  # JSON text, a bad message, then a good one
        ws.send(json.dumps({"qa": [1, 2]}))
        assert json.loads(ws.recv())["error"] == "InvalidInputError"
        ws.send(json.dumps({"qa": [1e308, 0.2, 0.3]}))  # (beyond the coordinates' bound: refused, never wrapped)
        assert "beyond 1e+06" in json.loads(ws.recv())["message"]
        ws.send("not json")
        assert json.loads(ws.recv())["error"] == "BadMessage"
        ws.send(json.dumps({"qa": qa[0].tolist()}))
        assert np.abs(np.array(json.loads(ws.recv())["q"]) - q).max() <= 1e-10
    from websockets.exceptions import InvalidStatus

    with pytest.raises(InvalidStatus) as refused, connect(url):  # (no token: refused before the handshake ends)
        pass
    assert refused.value.response.status_code == 403


def test_the_stream_reads_units_as_http_does_and_answers_with_units(client, service, delta):
    """A stream's message takes the unit strings an HTTP body takes (``"-30deg"``, ``"-30deg/s"``): the answer is the
    SI numbers' to 1e-12, with the HTTP answers' ``units``; a unit of the wrong kind is refused naming the entry and
    its unit (it was "got an array of <U32", with no unit)."""
    from pkm.client import ServiceError

    qa = delta.actuated_q(delta.q_reference)
    si = {"qa": [np.deg2rad(-30.0), qa[1], qa[2]], "qd": [0.0, 0.0, -np.pi / 6], "qdd": [1.0, 0.0, 0.0]}
    with client.stream("delta") as s:
        plain = s.send(**si)
    with client.stream("delta") as s:
        units = s.send(qa=["-30deg", qa[1], qa[2]], qd=["0", "0rpm", "-30deg/s"], qdd=[1.0, 0.0, 0.0])
        with pytest.raises(ServiceError) as wrong:
            s.send(qa=qa, qd=["1deg", 0.0, 0.0])
    for key in ("q", "yd", "tau"):
        assert np.abs(np.asarray(units[key]) - plain[key]).max() <= 1e-12 * max(1.0, np.abs(plain[key]).max())
    http = client.dynamics("delta", qa=si["qa"], qd=si["qd"])["units"]
    assert units["units"]["qd"] == ["rad/s"] * 3 and units["units"]["q"] == http["q"]
    assert units["units"]["tau"] == ["N m"] * 3 and units["units"]["qa"] == ["rad"] * 3
    assert wrong.value.kind == "UnitError" and "qd[0]" in str(wrong.value) and "[rad/s]" in str(wrong.value)


def test_a_msgpack_answer_decodes_by_the_documented_layout_without_pkm(service, delta):
    """The layout the docs state (docs/tour/robot.md, the schemas, pkm.serve.wire.ND_LAYOUT): extension type 1, its
    payload msgpack ``[dtype, shape, data]``, C order; decoded here by msgpack alone, a request's arrays sent as
    plain msgpack lists, the answer equal to the library's."""
    import msgpack

    from pkm.serve.wire import ND_LAYOUT

    def ext_hook(code, payload):
        assert code == 1
        dtype, shape, data = msgpack.unpackb(payload)
        assert len(data) == int(np.prod(shape)) * np.dtype(dtype).itemsize
        return np.frombuffer(data, dtype=dtype).reshape(shape)

    qa = _path(delta, 2)
    r = http.post(service.url + "/models/delta/fk", content=msgpack.packb({"qa": qa.tolist()}),
                   headers={**AUTH, "content-type": "application/msgpack", "accept": "application/msgpack"})
    answer = msgpack.unpackb(r.content, ext_hook=ext_hook)
    assert r.status_code == 200 and answer["q"].shape == (2, delta.nq) and answer["q"].dtype == np.dtype("<f8")
    q = pkm.close_loops(delta, qa[0], delta.q_reference).q
    assert np.abs(answer["q"][0] - q).max() <= 1e-10
    assert answer["iterations"].dtype.kind == "i"
    schema = http.get(service.url + "/openapi.json", headers=AUTH).json()
    assert ND_LAYOUT in schema["info"]["description"] and ND_LAYOUT in json.dumps(schema["components"]["schemas"])


def test_the_limiter_answers_busy_when_the_queue_is_full():
    from pkm.serve.app import Limiter, _Busy

    async def main() -> list:
        import time

        limiter = Limiter(workers=1, queue=1)
        slow = lambda: time.sleep(0.2)
        return await asyncio.gather(limiter.run(slow), limiter.run(slow), limiter.run(slow), return_exceptions=True)

    results = asyncio.run(main())
    assert sum(isinstance(r, _Busy) for r in results) == 1 and results.count(None) == 2


def test_the_compute_limit_answers_while_the_slot_stays_held():
    from pkm.serve.app import Limiter, _TooSlow

    async def main() -> tuple:
        import time

        limiter = Limiter(workers=1, queue=4)
        slow = asyncio.ensure_future(limiter.run(lambda: time.sleep(0.3), timeout=0.05))
        try:
            await slow
        except _TooSlow as e:
            first = e
        t0 = time.perf_counter()
        await limiter.run(lambda: None)  # (waits for the slow one's thread to end: the slot was held)
        return first, time.perf_counter() - t0

    err, waited = asyncio.run(main())
    assert "compute-time limit" in str(err) and waited > 0.15


def test_a_short_fuzz_gets_no_500_and_the_service_goes_on(service):
    """300 malformed requests (:mod:`pkm.serve.fuzz`; CI sends 10,000 to a service of its own): none answered 500,
    every error JSON with a message, no fk or ik of a coordinate beyond 1e6 (SI) answered as a success, the service
    answering afterwards."""
    from pkm.serve.fuzz import fuzz

    out = fuzz(service.url, 300, token=TOKEN, seed=1)
    assert out["failures"] == [] and out["alive"]
    assert {400, 401, 404, 413, 422} <= set(out["statuses"])


def test_jobs_run_apart_and_give_json_and_parquet(client, service, delta):
    """A map job with the capability index, every assembly mode of the 3-RRR, a failing job and a cancelled one."""
    import io

    import pyarrow.parquet as pq

    job = client.job("delta", "map", axes={"x": [-0.1, 0.1, 7], "y": [-0.05, 0.05, 5]}, fixed={"z": -0.35},
                     index="wrench")
    assert job["state"] in ("queued", "running", "done")
    result = client.result(job["id"])
    wmap = pkm.workspace_map(delta, {"x": np.linspace(-0.1, 0.1, 7), "y": np.linspace(-0.05, 0.05, 5)}, {"z": -0.35})
    assert np.array_equal(result["reachable"], wmap.reachable) and result["nodes"] == wmap.nodes
    assert result["capability"]["units"]["x"] == "N" and result["capability"]["isotropic"]["N"].shape == (5, 7)
    table = pq.read_table(io.BytesIO(http.get(f"{client.url}/jobs/{job['id']}/result", params={"format": "parquet"},
                                               headers=AUTH).content))
    assert table.num_rows == 35 and {"x", "y", "reachable", "ci_2", "isotropic [N]"} <= set(table.column_names)
    rrr3 = pkm.load("rrr3")
    modes = client.result(client.job("rrr3", "assembly_modes", qa=rrr3.actuated_q(rrr3.q_reference))["id"])
    direct = pkm.assembly_modes(rrr3, rrr3.actuated_q(rrr3.q_reference))
    assert modes["count"] == len(direct.modes) >= 2 and np.abs(modes["q"] - np.array([m.q for m in direct.modes])).max() < 1e-9
    assert [[o["joint"] for o in m] for m in modes["outside_limits"]] == [list(m.outside_limits) for m in direct.modes]
    from pkm.client import ServiceError

    bad = client.job("delta", "working_modes", y=[1.0, 2.0])  # (a wrong size: the job fails, with the message)
    with pytest.raises(ServiceError) as e:
        client.result(bad["id"])
    assert e.value.status == 422 and e.value.kind == "InvalidInputError" and "y" in e.value.message
    assert e.value.data["state"] == "failed"  # (the job's summary rides along)
    assert client.cancel(bad["id"])["state"] == "failed"  # (a finished job: forgotten)
    with pytest.raises(ServiceError) as e:
        client.job("delta", "teleport")
    assert e.value.status == 404 and {j["id"] for j in client._answer(client._http.get("/jobs"))["jobs"]} >= {job["id"]}


def test_a_registered_mechanism_with_other_parameters(client, service):
    """``GET /models/delta/parameters`` lists the design parameters; ``POST /models/delta/variants`` builds one (the
    same as ``pkm.build``), listed, queried; a parameter pkm refuses is 422 naming it."""
    from pkm.client import ServiceError

    info = client._answer(client._http.get("/models/delta/parameters"))
    names = {p["name"]: p for p in info["parameters"]}
    assert info["registered"] == "delta" and "R" in names and names["R"]["units"] == ["m"]
    entry = client._answer(client._http.post("/models/delta/variants", json={"params": {"R": 0.16}}))
    assert entry["kind"] == "variant" and entry["id"].startswith("delta@")
    built = pkm.build("delta", R=0.16)
    out = client.fk(entry["id"], built.actuated_q(built.q_reference))
    assert np.abs(out["q"][0] - pkm.close_loops(built, built.actuated_q(built.q_reference)).q).max() <= 1e-12
    with pytest.raises(ServiceError) as e:
        client._answer(client._http.post("/models/delta/variants", json={"params": {"R": -1.0}}))
    assert e.value.status == 422 and "R" in e.value.message


def test_a_sweep_job_is_pkm_sweep(client):
    """A design sweep as a job (serial here: CI's two cores; a local Dask cluster by default) equals
    :func:`pkm.sweep` of the same grid, and its rows come as Parquet too; its JSON answer matches its schema."""
    import io

    import pyarrow.parquet as pq

    from pkm import sweeps
    from tests.serve.test_schemas import Checker

    job = client.job("delta", "sweep", grid={"R": "10cm:20cm:3"}, objectives=["condition"], scheduler="serial")
    result = client.result(job["id"])
    answer = http.get(f"{client.url}/jobs/{job['id']}/result", headers=AUTH)
    Checker(http.get(client.url + "/openapi.json", headers=AUTH).json())("job_result", answer)  # (its schema)
    direct = sweeps.sweep("delta", sweeps.grid(R="10cm:20cm:3"), ["condition"], scheduler="serial", progress=False)
    assert result["designs"] == 3 and result["failed"] == 0
    assert np.allclose(result["rows"]["condition"], direct.table.column("condition").to_pylist(), rtol=1e-12)
    table = pq.read_table(io.BytesIO(http.get(f"{client.url}/jobs/{job['id']}/result", params={"format": "parquet"},
                                               headers=AUTH).content))
    assert table.num_rows == 3 and "condition" in table.column_names


def test_the_compiled_batches_answer_as_the_python_route(client, delta):
    """A batch's FK, Jacobians and dynamics run on the compiled kernels in the service: the same answers as the
    Python route (queries called without kernels) to 1e-10, iterations integers both ways; a batch with a sample the
    loops cannot close (the 3-PRS's sliders 1 m apart) gives the same statuses and nulls both ways."""
    from pkm.serve import queries

    qa = _path(delta, 4)
    for name, body in (("fk", {"qa": qa}), ("jacobians", {"qa": qa}),
                       ("dynamics", {"qa": qa, "qd": [0.1, 0.0, 0.0], "qdd": [1.0, 0.0, 0.0]})):
        served, local = client.query("delta", name, **body), queries.QUERIES[name](delta, body, None)
        assert served["status"] == local["status"] == ["ok"] * 4
        assert served["outside_limits"] == local["outside_limits"] == [[]] * 4
        for key in set(local) - {"status", "units", "outside_limits"}:
            assert np.abs(np.asarray(served[key], dtype=float) - local[key]).max() <= 1e-10, (name, key)
    assert served["units"] == local["units"] and served["units"]["M"][0][0] == "N m/(rad/s^2)"
    assert client.fk("delta", qa)["iterations"].dtype.kind == "i"
    prs3 = pkm.load("prs3")
    qa = [prs3.actuated_q(prs3.q_reference).tolist(), [0.6, -0.4, 0.6]] * 2
    served, local = client.fk("prs3", qa), queries.fk(prs3, {"qa": qa})
    assert served["status"] == local["status"] == ["ok", "failed"] * 2 and served["q"][1] is local["q"][1] is None
    assert [f["error"] for f in served["failures"]] == [f["error"] for f in local["failures"]] == ["ConvergenceError"] * 2
    assert np.abs(served["q"][2] - local["q"][2]).max() <= 1e-12 and isinstance(served["iterations"][0], int)
