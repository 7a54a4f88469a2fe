"""A client generated from the service's schema works: CI's proof that ``/openapi.json`` is a contract.

Starts a real ``pkm serve`` (its own process, on a free port of 127.0.0.1, with a token), fetches ``/openapi.json``,
generates a Python client from it with openapi-python-client (the ``contract`` extra: ``pip install -e ".[contract]"``)
into a temporary folder, imports the generated package and, through it only, runs the forward kinematics, the inverse
kinematics (unit strings; a batch with an unreachable sample; one unreachable sample: its 422), the inverse dynamics
(at actuated values), an upload (examples/humanoid_ankle's files, then its FK) and a job (a workspace map: start,
poll, result), each answer checked against pkm called in this process. Prints what it did; exit status 1 on any
failure.

Usage: ``python tools/generated_client.py [--generator PATH] [--keep DIR]``.
"""

from __future__ import annotations

import argparse
import importlib
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
TOKEN = "contract-token"
PACKAGE = "pkm_generated"


def generator(path: str | None) -> str:
    """The openapi-python-client command: ``path``, or the one beside this Python, or on PATH."""
    if path:
        return path
    beside = Path(sys.executable).parent / "openapi-python-client"
    found = str(beside) if beside.exists() else shutil.which("openapi-python-client")
    if not found:
        raise SystemExit("openapi-python-client is not installed: pip install -e \".[contract]\"")
    return found


def generate(url: str, folder: Path, command: str) -> Any:
    """The client generated from ``url``'s schema into ``folder``, imported."""
    import httpx

    spec = folder / "openapi.json"
    spec.write_text(json.dumps(httpx.get(url + "/openapi.json", headers={"authorization": f"Bearer {TOKEN}"}).json()))
    run = subprocess.run([command, "generate", "--path", str(spec), "--meta", "none", "--output-path",
                          str(folder / PACKAGE)], capture_output=True, text=True, cwd=folder)
    if run.returncode != 0 or not (folder / PACKAGE / "__init__.py").exists():
        raise RuntimeError(f"openapi-python-client failed ({run.returncode}):\n{run.stdout}\n{run.stderr}")
    skipped = sorted({line.split(" within ")[0] for line in (run.stdout + run.stderr).splitlines()
                      if "WARNING parsing" in line})
    print(f"  generated {PACKAGE} ({len(list((folder / PACKAGE).rglob('*.py')))} modules); the msgpack body of "
          f"{len(skipped)} operations not generated (JSON only: openapi-python-client has no msgpack)")
    sys.path.insert(0, str(folder))
    return importlib.import_module(PACKAGE)


def close(a: Any, b: Any, tol: float, what: str) -> None:
    err = float(np.abs(np.asarray(a, dtype=float) - np.asarray(b, dtype=float)).max())
    if not err <= tol:
        raise AssertionError(f"{what}: differs by {err:.3g} > {tol:g}")
    print(f"  {what}: agrees with pkm to {err:.1e}")


def exercise(url: str, folder: Path) -> None:
    """FK, IK, dynamics, an upload and a job through the generated client (see the module doc)."""
    import pkm

    gen = importlib.import_module(PACKAGE)
    api = importlib.import_module(f"{PACKAGE}.api")
    models = importlib.import_module(f"{PACKAGE}.models")
    types = importlib.import_module(f"{PACKAGE}.types")
    for part in ("queries.fk", "queries.ik", "queries.dynamics", "models.upload", "jobs.job_map", "jobs.job_state",
                 "jobs.job_result", "service.health"):
        importlib.import_module(f"{api.__name__}.{part}")
    client = gen.AuthenticatedClient(base_url=url, token=TOKEN, raise_on_unexpected_status=True, timeout=120)
    print(f"  health: {api.service.health.sync(client=client).status}")

    delta = pkm.load("delta")
    qa = (delta.actuated_q(delta.q_reference) + 0.05).tolist()
    fk = api.queries.fk.sync(model="delta", client=client, body=models.FkRequest(qa=qa))
    assert isinstance(fk, models.FkAnswer), fk
    assert [s.value for s in fk.status] == ["ok"] and isinstance(fk.iterations[0], int), fk
    close(fk.q[0], pkm.close_loops(delta, qa).q, 1e-10, "FK (delta, one sample)")

    y = [0.0, "5mm", "-35cm"]
    ik = api.queries.ik.sync(model="delta", client=client, body=models.IkRequest(y=y))
    assert isinstance(ik, models.IkAnswer), ik
    close(ik.qa[0], delta.actuated_q(pkm.solve_ik(delta, [0.0, 0.005, -0.35]).q), 1e-9, "IK (unit strings)")
    batch = api.queries.ik.sync(model="delta", client=client, body=models.IkRequest(y=[[0.0, 0.0, -0.35],
                                                                                        [0.0, 0.0, -3.0]]))
    assert [s.value for s in batch.status] == ["ok", "failed"] and batch.q[1] is None, batch
    print(f"  IK batch with an unreachable sample: status {[s.value for s in batch.status]}, "
          f"{batch.failures[0].error} for sample {batch.failures[0].sample}, its q null")
    failed = api.queries.ik.sync_detailed(model="delta", client=client, body=models.IkRequest(y=[0.0, 0.0, -3.0]))
    assert failed.status_code == 422 and isinstance(failed.parsed, models.ErrorAnswer), failed
    print(f"  IK of one unreachable sample: {int(failed.status_code)} {failed.parsed.error}")

    qdd = [1.0, 0.0, 0.0]
    dyn = api.queries.dynamics.sync(model="delta", client=client,
                                    body=models.DynamicsRequest(qa=qa, qd=[0.1, 0.0, 0.0], qdd=qdd))
    assert isinstance(dyn, models.DynamicsAnswer), dyn
    m = pkm.actuator_model(delta, pkm.close_loops(delta, qa).q, [0.1, 0.0, 0.0])
    close(dyn.tau[0], m.M @ np.array(qdd) + m.h, 1e-9, f"inverse dynamics at qa [{', '.join(dyn.units['tau'])}]")

    files = [ROOT / "examples" / "humanoid_ankle" / name for name in ("ankle.xml", "ankle.closures.toml")]
    body = models.Upload(files=[types.File(payload=f.open("rb"), file_name=f.name) for f in files])
    entry = api.models.upload.sync(client=client, body=body)
    assert isinstance(entry, models.ModelEntry), entry
    ankle = pkm.load(files[1])
    out = api.queries.fk.sync(model=entry.id, client=client, body=models.FkRequest(qa=[0.1, -0.1]))
    close(out.y[0], pkm.TaskMap.of(ankle).value(pkm.close_loops(ankle, [0.1, -0.1]).q), 1e-10,
          f"upload {entry.name} ({entry.id}) and its FK")

    axes = models.MapJobAxes.from_dict({"x": [-0.05, 0.05, 5], "y": [-0.05, 0.05, 3]})
    job = api.jobs.job_map.sync(model="delta", client=client,
                                body=models.MapJob(axes=axes, fixed=models.MapJobFixedType0.from_dict({"z": -0.35})))
    assert isinstance(job, models.JobState), job
    for _ in range(1200):
        state = api.jobs.job_state.sync(job_id=job.id, client=client)
        if state.state.value not in ("queued", "running"):
            break
        time.sleep(0.05)
    assert state.state.value == "done", state
    result = api.jobs.job_result.sync(job_id=job.id, client=client)
    assert isinstance(result, models.JobResult) and isinstance(result.result, models.MapResult), result
    wmap = pkm.workspace_map(delta, {"x": np.linspace(-0.05, 0.05, 5), "y": np.linspace(-0.05, 0.05, 3)},
                             {"z": -0.35})
    assert result.result.nodes == wmap.nodes, (result.result.nodes, wmap.nodes)
    print(f"  map job {job.id}: {state.state.value}, {result.result.nodes} reachable nodes (pkm: {wmap.nodes})")


def main(argv: list[str] | None = None) -> int:
    from pkm.serve.process import start

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--generator", help="the openapi-python-client command (default: beside this Python, or PATH)")
    ap.add_argument("--keep", type=Path, help="generate into this folder and keep it (default: a temporary one)")
    args = ap.parse_args(argv)
    command = generator(args.generator)
    t0 = time.perf_counter()
    proc, url = start("--token", TOKEN)
    print(f"generated client: pkm serve at {url}")
    try:
        with tempfile.TemporaryDirectory() as tmp:
            folder = args.keep or Path(tmp)
            folder.mkdir(parents=True, exist_ok=True)
            generate(url, folder, command)
            exercise(url, folder)
    except Exception as e:
        print(f"generated client: FAILED: {type(e).__name__}: {e}")
        return 1
    finally:
        proc.terminate()
        proc.wait(timeout=60)
    print(f"generated client: FK, IK, dynamics, an upload and a job through the generated client, all as pkm; "
          f"{time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
