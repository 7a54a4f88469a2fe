"""The service's typed contract (:mod:`pkm.serve.schemas`): ``/openapi.json`` has one operation per query and job kind,
each with a request and an answer schema with examples; real answers of every operation (JSON, through a real
uvicorn: tests/serve/conftest.py) validate against the schemas it publishes, so that the declared schema cannot drift
from what the service answers."""

from __future__ import annotations

import time
from pathlib import Path

import httpx
import numpy as np
import pytest

from tests import http
from tests.serve.conftest import TOKEN

AUTH = {"authorization": f"Bearer {TOKEN}"}
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
QUERIES = ("fk", "ik", "jacobians", "diagnose", "velocities", "dynamics", "capability", "scene", "stiffness")


@pytest.fixture(scope="module")
def openapi(service) -> dict:
    return http.get(service.url + "/openapi.json", headers=AUTH).json()


def _operations(openapi: dict) -> dict[str, tuple[str, str, dict]]:
    return {op["operationId"]: (method, path, op) for path, item in openapi["paths"].items()
            for method, op in item.items()}


class Checker:
    """Validates answers against the answer schema ``openapi`` gives their operation and status."""

    def __init__(self, openapi: dict):
        self.openapi, self.operations, self.seen = openapi, _operations(openapi), set()

    def __call__(self, operation: str, r: httpx.Response) -> dict:
        import jsonschema

        _, _, op = self.operations[operation]
        response = op["responses"][str(r.status_code)]
        schema = response["content"]["application/json"]["schema"]
        body = r.json()
        error = jsonschema.exceptions.best_match(jsonschema.Draft202012Validator(
            {**schema, "components": self.openapi["components"]}).iter_errors(body))
        if error is not None:
            raise error
        assert "NaN" not in r.text and '"nan"' not in r.text
        self.seen.add((operation, r.status_code))
        return body


def test_one_typed_operation_per_query_with_examples(openapi):
    ops = _operations(openapi)
    components = openapi["components"]["schemas"]
    for name in QUERIES:
        method, path, op = ops[name]
        assert (method, path) == ("post", f"/models/{{model}}/{name}") and op["tags"] == ["queries"]
        body = op["requestBody"]["content"]
        assert set(body) == {"application/json", "application/msgpack"}
        request = components[body["application/json"]["schema"]["$ref"].rsplit("/", 1)[1]]
        answer = components[op["responses"]["200"]["content"]["application/json"]["schema"]["$ref"].rsplit("/", 1)[1]]
        assert request["additionalProperties"] is False
        for schema in (request, answer):  # (every field described, with an example)
            for field, prop in schema["properties"].items():
                assert prop.get("description") and "examples" in prop, (name, field)
        assert {"200", "404", "422"} <= set(op["responses"])
        model = op["parameters"][0]
        assert model["name"] == "model" and "delta" in model["schema"]["examples"]
        assert "GET /models" in model["schema"]["description"]
    for kind in ("assembly_modes", "working_modes", "map", "sweep"):
        assert ops[f"job_{kind}"][1] == f"/models/{{model}}/jobs/{kind}"
    assert "{query}" not in "".join(openapi["paths"])  # (the queries are enumerated by their operations)


def test_the_check_sees_a_drift(openapi):
    """An answer with a field its schema does not declare, or a number as a string, is refused by the check."""
    import jsonschema

    check = Checker(openapi)
    good = {"status": ["ok"], "outside_limits": [[]], "q": [[0.1]], "y": [[0.0]], "residual": [0.0],
            "iterations": [3], "units": {}, "compute_s": 0.001}
    check("fk", httpx.Response(200, json=good))
    for bad in ({**good, "extra": 1}, {**good, "iterations": [3.5]}, {**good, "residual": ["nan"]},
                {k: v for k, v in good.items() if k != "outside_limits"}, {**good, "status": ["outside"]},
                {**good, "outside_limits": [["motor_1"]]}):
        with pytest.raises(jsonschema.ValidationError):
            check("fk", httpx.Response(200, json=bad))


def test_every_answer_matches_its_published_schema(service, openapi):
    """Every operation answering JSON, each query as one sample and as a batch with a failed sample, the errors (404,
    409, 422, a failed job's 422, a cancelled job's 410): validated against /openapi.json."""
    check = Checker(openapi)
    url = service.url

    def call(operation: str, path: str, *, method: str = "post", status: int = 200, **kw) -> dict:
        r = http.request(method, url + path, headers=AUTH, timeout=120, **kw)
        assert r.status_code == status, (operation, r.text)
        return check(operation, r)

    check("health", http.get(url + "/health"))
    call("list_models", "/models", method="get")
    about = call("describe_model", "/models/delta", method="get")
    call("describe_model", "/models/nope", method="get", status=404)
    call("parameters", "/models/delta/parameters", method="get")
    variant = call("variant", "/models/delta/variants", status=201, json={"params": {"R": "16cm"}})
    assert variant["kind"] == "variant"
    files = [EXAMPLES / "humanoid_ankle" / "ankle.xml", EXAMPLES / "humanoid_ankle" / "ankle.closures.toml"]
    entry = call("upload", "/models", status=201, files=[("files", (f.name, f.read_bytes())) for f in files])
    call("model_files", f"/models/{entry['id']}/files", method="get")
    outside = call("ik", f"/models/{entry['id']}/ik", json={"y": [[0.8, 0.0], [0.3, 0.0]]})  # (pitch range +-0.6)
    assert outside["status"] == ["outside_limits", "ok"] and outside["outside_limits"][1] == []
    assert [o["joint"] for o in outside["outside_limits"][0]] == ["ankle_pitch", "motor_left", "motor_right"]

    q0, qa0 = np.array(about["q_reference"]), np.array(about["q_reference"])[about["actuated_q"]]
    batch = [qa0.tolist(), (qa0 + 0.02).tolist()]
    one = {"fk": {"qa": qa0.tolist()}, "ik": {"y": [0.0, 0.0, "-35cm"]},
           "velocities": {"qa": qa0.tolist(), "qd": [0.1, 0.0, 0.0], "qdd": [1.0, 0.0, 0.0]},
           "dynamics": {"q": q0.tolist(), "qd": [0.1, 0.0, 0.0], "qdd": [1.0, 0.0, 0.0]},
           "capability": {"qa": qa0.tolist(), "kind": "twist"},
           "stiffness": {"qa": qa0.tolist(), "drives": 500.0, "wrench": [0.0, 0.0, -10.0, 0.0, 0.0, 0.0]}}
    gs = call("describe_model", "/models/gough_stewart", method="get")  # (a design whose files carry collision geometry)
    gs_qa0 = np.array(gs["q_reference"])[gs["actuated_q"]]
    call("clearance", "/models/gough_stewart/clearance", json={"qa": gs_qa0.tolist()})
    call("clearance", "/models/gough_stewart/clearance", json={"qa": [gs_qa0.tolist(), (gs_qa0 + 0.02).tolist()]})
    for name in QUERIES:
        single = one.get(name, {"qa": qa0.tolist()})
        out = call(name, f"/models/delta/{name}", json=single)
        assert out["status"] == ["ok"] and "failures" not in out and out["compute_s"] > 0
        many = {**single, **({"y": [[0.0, 0.0, -0.35], [0.0, 0.0, -3.0]]} if name == "ik" else
                              {"q": [q0.tolist(), q0.tolist()]} if "q" in single else {"qa": batch})}
        out = call(name, f"/models/delta/{name}", json=many)
        assert len(out["status"]) == 2
    failed = call("ik", "/models/delta/ik", json={"y": [[0.0, 0.0, -0.35], [0.0, 0.0, -3.0]]})
    assert failed["status"] == ["ok", "failed"] and failed["q"][1] is None and failed["failures"][0]["sample"] == 1
    call("ik", "/models/delta/ik", status=422, json={"y": [0.0, 0.0, -3.0]})  # (one sample: pkm's error)
    call("fk", "/models/delta/fk", status=422, json={"qa": qa0.tolist(), "foo": 1})  # (an unknown field)
    absurd = call("fk", "/models/delta/fk", status=422, json={"qa": [1e308, 0.2, 0.3]})  # (never wrapped to 2.58 rad)
    assert absurd["error"] == "InvalidInputError" and "beyond 1e+06" in absurd["message"]
    call("fk", "/models/nope/fk", status=404, json={"qa": qa0.tolist()})

    jobs = {"job_map": ("map", {"axes": {"x": [-0.05, 0.05, 3], "y": [-0.05, 0.05, 2]}, "fixed": {"z": -0.35},
                                "index": "wrench"}),
            "job_working_modes": ("working_modes", {"y": [0.0, 0.0, -0.35]})}
    started = {op: call(op, f"/models/delta/jobs/{kind}", status=202, json=body) for op, (kind, body) in jobs.items()}
    rrr3 = http.get(url + "/models/rrr3", headers=AUTH).json()
    qa_rrr3 = np.array(rrr3["q_reference"])[rrr3["actuated_q"]].tolist()
    started["job_assembly_modes"] = call("job_assembly_modes", "/models/rrr3/jobs/assembly_modes", status=202,
                                         json={"qa": qa_rrr3})
    call("job_map", "/models/delta/jobs/map", status=422, json={"axes": {"x": [0, 1, 3]}, "what": 1})
    late = call("job_working_modes", "/models/delta/jobs/working_modes", status=202, json={"y": [0.0, 0.0, -0.35]})
    assert call("cancel_job", f"/jobs/{late['id']}", method="delete")["state"] == "cancelled"  # (queued: one worker)
    call("job_result", f"/jobs/{late['id']}/result", method="get", status=410)
    for job in started.values():
        for _ in range(1200):
            state = call("job_state", f"/jobs/{job['id']}", method="get")
            if state["state"] not in ("queued", "running"):
                break
            time.sleep(0.05)
        assert state["state"] == "done", state
        call("job_result", f"/jobs/{job['id']}/result", method="get")
    bad = call("job_working_modes", "/models/delta/jobs/working_modes", status=202, json={"y": [1.0, 2.0]})
    while call("job_state", f"/jobs/{bad['id']}", method="get")["state"] in ("queued", "running"):
        time.sleep(0.05)
    failed = call("job_result", f"/jobs/{bad['id']}/result", method="get", status=422)  # (the job's own error)
    assert failed["error"] == "InvalidInputError" and failed["data"]["state"] == "failed"
    call("list_jobs", "/jobs", method="get")
    call("cancel_job", f"/jobs/{started['job_map']['id']}", method="delete")
    call("job_state", "/jobs/nope", method="get", status=404)
    json_operations = {op for op, (_, _, spec) in check.operations.items()
                       if any("application/json" in spec["responses"].get(code, {}).get("content", {})
                              for code in ("200", "201", "202"))}
    # (every operation answering JSON checked, but the sweep: its answer is checked in test_a_sweep_job_is_pkm_sweep)
    assert json_operations - {op for op, _ in check.seen} == {"job_sweep"}


def test_the_token_is_a_declared_bearer_scheme(openapi, service):
    """A service with a token declares the bearer scheme on every operation but ``/`` and ``/health`` (Swagger UI's
    Authorize then sends the header); the declared operations refuse a request without it, the exempt ones do not."""
    assert openapi["components"]["securitySchemes"]["bearer"] == {
        "type": "http", "scheme": "bearer", "description": "the token `pkm serve --token` was given"}
    for path, item in openapi["paths"].items():
        for op in item.values():
            assert op["security"] == ([] if path in ("/", "/health") else [{"bearer": []}]), path
    assert http.get(service.url + "/health").status_code == 200
    assert http.get(service.url + "/models").status_code == 401
