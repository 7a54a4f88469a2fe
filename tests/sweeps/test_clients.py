"""The Dask clients and clusters a sweep makes are closed when it returns or raises, never left to the garbage
collector: a process that runs many sweeps (a notebook, a service, the fuzz harness) holds none of them afterwards.

A client left to the collector is a hazard, not just a leak: its ``__del__`` closes it from wherever the collector
happens to run, and when that is inside the next ``Client()``'s start, both wait on dask's one loop-runner lock
and the process hangs for good (what the full fuzz report ran into)."""

from __future__ import annotations

import gc
import threading

import pytest

import pkm
from pkm import sweeps
from pkm.errors import InvalidInputError, SweepError
from pkm.sweeps import engine

TINY = sweeps.table({"h": [0.1, 0.15]})
FAILS = sweeps.table({"h": [-0.1, -0.2]})  # every design fails (a negative length)


def _in_process_cluster():
    from dask.distributed import LocalCluster

    return LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0")  # (no port clash)


def _unclosed_clients() -> list:
    """Clients still registered as default (dask keeps them weakly: only a client left unclosed is there with the
    collector off) or still open among the live objects."""
    from distributed.client import Client, _global_clients

    live = [o for o in gc.get_objects() if isinstance(o, Client) and o.status not in ("closed", "closing")]
    return list(_global_clients.values()) + live


def test_no_client_or_cluster_outlives_a_sweep(monkeypatch):
    """With the collector off, sweeps that succeed, whose every design fails, whose scheduler address is malformed
    or unreachable, and one interrupted (KeyboardInterrupt) while its chunks run: none leaves a client open or its
    local cluster running, nor an extra IO-loop thread."""
    import dask

    loops_before = sum(t.name == "IO loop" for t in threading.enumerate())
    started: list = []

    def local(workers=None):  # the path that starts a cluster of its own, in threads (cheap)
        started.append(_in_process_cluster())
        return started[-1]

    monkeypatch.setattr(engine, "local_cluster", local)
    gc.collect()
    gc.disable()
    try:
        with _in_process_cluster() as cluster:
            address = cluster.scheduler_address
            res = pkm.sweep("rrr3", TINY, ["gci:step=5cm"], scheduler=address, progress=False)
            assert res.ok.all() and not _unclosed_clients()
            res = pkm.sweep("rrr3", FAILS, ["gci:step=5cm"], scheduler=address, progress=False)
            assert res.stats.failed == 2 and not _unclosed_clients()
            res = pkm.sweep("rrr3", TINY, ["gci:step=5cm"], progress=False)  # its own (patched) local cluster
            assert res.ok.all() and not _unclosed_clients()
            assert started and started[-1].status.name == "closed"
            for bad in ("abc", "tcp://127.0.0.1:9"):
                with dask.config.set({"distributed.comm.timeouts.connect": "0.5s"}), \
                        pytest.raises(SweepError, match="cannot reach"):
                    pkm.sweep("rrr3", TINY, ["gci:step=5cm"], scheduler=bad, progress=False)
                assert not _unclosed_clients(), bad

            def interrupted(*args):
                raise KeyboardInterrupt

            monkeypatch.setattr(engine, "_bar", interrupted)
            for sched in (address, None):
                with pytest.raises(KeyboardInterrupt):
                    pkm.sweep("rrr3", TINY, ["gci:step=5cm"], scheduler=sched, progress=False)
                assert not _unclosed_clients(), sched
            assert started[-1].status.name == "closed"
            from dask.distributed import Client

            closed = Client(cluster, set_as_default=False)
            closed.close()
            with pytest.raises(InvalidInputError, match="the client is closed"):
                pkm.sweep("rrr3", TINY, ["gci:step=5cm"], client=closed, progress=False)
        assert sum(t.name == "IO loop" for t in threading.enumerate()) == loops_before
    finally:
        gc.enable()


def test_a_daemonic_process_is_told_at_once_it_cannot_start_local_workers(monkeypatch):
    """In a daemonic process (a multiprocessing pool's worker, the fuzz harness's), which may not have children,
    a sweep without a scheduler refuses the local cluster before starting it: a SweepError saying why and what
    to pass, not dask's nannies failing after seconds of tracebacks."""
    import multiprocessing
    import types

    monkeypatch.setattr(multiprocessing, "current_process", lambda: types.SimpleNamespace(daemon=True))
    with pytest.raises(SweepError, match=r"could not start 2 local Dask workers \(daemonic processes are not allowed"
                                         r" to have children.*scheduler='serial'"):
        pkm.sweep("rrr3", TINY, ["gci:step=5cm"], workers=2, progress=False)
