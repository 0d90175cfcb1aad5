"""A study on Dask gives the same variants, bit for bit, as in one process: on a
LocalCluster of two processes, and on a scheduler and two workers started with the `dask`
command line (127.0.0.1 only, killed whatever happens)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from pinmech.design.study.run import study
from pinmech.design.study.file import load_study

distributed = pytest.importorskip("distributed")
ROOT = Path(__file__).resolve().parents[1]
DASK = Path(sys.executable).parent / "dask"


def _small_spec():
    """The bundled tolerance study cut to 240 variants in 8 batches of 30 (seconds of work)."""
    spec = load_study(ROOT / "models" / "studies" / "four_bar_tolerance.toml")
    return spec.__class__(**{**spec.__dict__, "samples": 240, "batch": 30, "steps": 37})


def _start(args: list[str], log: Path) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    return subprocess.Popen([str(DASK), *args], stdout=log.open("w"), stderr=subprocess.STDOUT, env=env,
                            start_new_session=True, cwd=str(ROOT))


def _stop(proc: subprocess.Popen) -> None:
    """End the process we started and its children (its own process group), then reap it."""
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=10)


@pytest.fixture
def scheduler(tmp_path):
    """The address of a `dask scheduler` on 127.0.0.1 with two one-thread `dask worker`s."""
    if not DASK.is_file():
        pytest.skip(f"no dask command beside {sys.executable}")
    file = tmp_path / "scheduler.json"
    procs = [_start(["scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard", "--scheduler-file",
                     str(file)], tmp_path / "scheduler.log")]
    try:
        deadline = time.monotonic() + 60
        while not file.is_file() and time.monotonic() < deadline:
            time.sleep(0.2)
        assert file.is_file(), (tmp_path / "scheduler.log").read_text()
        address = json.loads(file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for i in range(2):
            procs.append(_start(["worker", address, "--nthreads", "1", "--nworkers", "1", "--no-dashboard",
                                 "--host", "127.0.0.1"], tmp_path / f"worker{i}.log"))
        with distributed.Client(address, timeout="30s") as client:
            client.wait_for_workers(2, timeout=90)
        yield address
    finally:
        for proc in reversed(procs):
            _stop(proc)


def _same(a, b) -> None:
    pa, ya, ca = a.variants
    pb, yb, cb = b.variants
    assert ca == cb
    np.testing.assert_array_equal(pa, pb)  # bit for bit: assert_array_equal, not allclose
    np.testing.assert_array_equal(ya, yb)
    np.testing.assert_array_equal(a.spread.sigma, b.spread.sigma)


def test_local_cluster_and_a_dask_command_line_cluster_give_the_serial_variants(scheduler):
    spec = _small_spec()
    serial = study(spec)
    assert serial.spread.solved == 240
    _same(serial, study(spec, workers=2))
    _same(serial, study(spec, scheduler=scheduler))


def test_the_variants_do_not_depend_on_the_order_batches_run_in():
    """Batch 3 alone, in a fresh process state, equals batch 3 of the whole run."""
    from pinmech.design.cluster import _BUILT, solve_batch
    from pinmech.design.study.tolerance import batches

    spec = _small_spec()
    whole = study(spec).batches[3]
    _BUILT.clear()
    alone = solve_batch(spec, batches(spec.samples, spec.batch)[3])
    np.testing.assert_array_equal(alone.p, whole.p)
    np.testing.assert_array_equal(alone.y, whole.y)


def test_each_worker_builds_the_mechanism_once_and_computes_on_one_thread():
    """8 batches on 2 workers: each worker built the study's mechanism once (not a batch), and
    its OpenMP and BLAS pools are one thread (nothing else competes for the two cores)."""
    from pinmech.design.cluster import run_batches
    from pinmech.design.study.tolerance import batches

    def state() -> tuple:
        from pinmech.design import cluster

        return cluster.BUILDS[0], os.environ.get("OMP_NUM_THREADS"), os.environ.get("OPENBLAS_NUM_THREADS")

    spec = _small_spec()
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address="127.0.0.1:0",
                                  host="127.0.0.1") as cluster, distributed.Client(cluster) as client:
        run_batches(spec, batches(spec.samples, spec.batch), scheduler=cluster.scheduler_address)
        seen = client.run(state)
    assert len(seen) == 2
    assert all(s == (1, "1", "1") for s in seen.values()), seen
