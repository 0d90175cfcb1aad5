"""Running a study's batches: in this process, on a `dask.distributed` LocalCluster of
worker processes (one thread each), or on an existing cluster by its scheduler address.

Each worker builds the study's mechanism once from its description (the StudySpec: file
paths and parameters; Pinocchio's constraint models do not pickle) and keeps it for the
batches it is sent. A batch's variants are drawn from the study's seed and the batch's
index (tolerance.py), so the results are the same bit for bit however many workers share
them, and in whatever order they finish: they are gathered in batch order.

A batch should hold 0.1 to 1 s of work (a Dask task costs about 3 ms here): the study
file's `batch` (variants a task) sets it; a four-bar variant over 73 poses takes ~0.2 ms.
Workers run one thread each, with OpenMP and BLAS pools of one thread (Dask's default
`distributed.nanny.pre-spawn-environ` sets OMP/MKL/OPENBLAS_NUM_THREADS=1 before a worker
starts; tests/test_cluster.py checks it).
"""

from __future__ import annotations

import os
import socket
from collections.abc import Callable, Iterator
from contextlib import contextmanager

from pinmech.design.study.file import StudySpec
from pinmech.design.study.tolerance import Batch, BatchResult, run_batch
from pinmech.exceptions import ClusterError, OptionError, PinmechError

_EXTRA = 'pip install "pinmech[study]"'
#: Seconds a scheduler given by its address has to answer (Dask's own default waits 30 s).
CONNECT_SECONDS = 5.0
_SCHEMES = ("tcp", "tls", "ws", "wss")
#: run(spec, batches, progress=None) -> results in batch order
Runner = Callable[..., list]
#: Dask settings of the workers pinmech starts. By default a worker samples its computing
#: thread's stack every 10 ms (the profiler), wakes its event loop every 20 ms (the tick
#: monitor) and reads its memory every 0.1 s; its scheduler and client answer. Measured on
#: the four-bar's tolerance study (2000 variants x 360 poses, 2 workers, 3 runs, the shared
#: 2-core machine at load 11): the workers used 1.74 .. 1.96 x the serial CPU time and the
#: client (with the LocalCluster's scheduler) 0.60 .. 0.86 s a run; quiet, 1.33 .. 1.47 x
#: and 0.17 .. 0.19 s. These costs grow with the wall time, so with the machine's load.
QUIET_WORKERS = {"distributed.worker.profile.enabled": False, "distributed.admin.tick.interval": "1s",
                 "distributed.admin.system-monitor.interval": "5s",
                 "distributed.worker.memory.monitor-interval": "5s"}
#: StudySpec -> (StudyMechanism, StudyOutputs), built once per process.
_BUILT: dict[StudySpec, tuple] = {}
#: How many times this process built a study's mechanism (a worker should once a study).
BUILDS = [0]


def require_dask():
    """dask.distributed, or an ImportError naming the extra that brings it."""
    try:
        import distributed
    except ImportError as exc:
        raise ImportError(f"running a study on Dask needs dask.distributed: {_EXTRA} ({exc})") from exc
    return distributed


def built(spec: StudySpec) -> tuple:
    """This process's (StudyMechanism, StudyOutputs) of the study, built on first use."""
    if spec not in _BUILT:
        from pinmech.design.study.outputs import StudyOutputs
        from pinmech.design.study.variant import StudyMechanism

        sm = StudyMechanism(spec)
        _BUILT[spec] = (sm, StudyOutputs(sm))
        BUILDS[0] += 1
    return _BUILT[spec]


def solve_batch(spec: StudySpec, batch: Batch) -> BatchResult:
    """One batch, on the mechanism this process built (a Dask task)."""
    if spec.kind == "workspace":
        from pinmech.design.workspace.batch import run_workspace_batch

        return run_workspace_batch(spec, batch)
    sm, outputs = built(spec)
    if spec.kind == "grid":
        from pinmech.design.study.grid import run_grid_batch

        return run_grid_batch(sm, outputs, batch)
    return run_batch(sm, outputs, batch)


def run_batches(spec: StudySpec, batches: list[Batch], *, workers: int = 0, scheduler: str | None = None,
                progress: Callable[[Batch], None] | None = None) -> list[BatchResult]:
    """Every batch's result, in batch order.

    Args:
        workers: 0 solves them in this process; n > 0 on a LocalCluster of n worker
            processes of one thread each (unless a scheduler is given).
        scheduler: a running scheduler's address ("tcp://127.0.0.1:8786"); the CLI takes
            it from --scheduler or $DASK_SCHEDULER_ADDRESS (`scheduler_address`).
        progress: called with each batch as it finishes (on Dask: in the order they finish).
    """
    with batch_runner(workers=workers, scheduler=scheduler) as run:
        return run(spec, batches, progress)


@contextmanager
def batch_runner(*, workers: int = 0, scheduler: str | None = None) -> Iterator[Runner]:
    """A `run(spec, batches, progress)` for several rounds of batches on one cluster (a
    workspace study's grid, then its refinement levels): in this process (workers 0, no
    scheduler), on a LocalCluster started once, or on the scheduler given."""
    if scheduler is None and workers == 0:
        yield _serial
        return
    distributed = require_dask()
    if scheduler is not None:
        with connected(scheduler, distributed) as client:
            yield lambda spec, todo, progress=None: _gathered(client, spec, todo, progress, distributed, scheduler)
        return
    with local_cluster(workers) as cluster, distributed.Client(cluster) as client:
        yield lambda spec, todo, progress=None: _gathered(client, spec, todo, progress, distributed, "local")


@contextmanager
def connected(address: str, distributed) -> Iterator:
    """A Client of the scheduler at `address`, in CONNECT_SECONDS or a ClusterError: the
    address checked first (scheme://host:port), then a TCP connection tried, then Dask's
    handshake (a server that is no scheduler fails there)."""
    host, port = _host_port(address)
    try:
        socket.create_connection((host, port), timeout=CONNECT_SECONDS).close()
    except OSError as exc:
        raise ClusterError(f"cannot reach {host}:{port} within {CONNECT_SECONDS:g} s ({exc}): is the scheduler "
                           "running, and is this its address?", address=address) from None
    client = _handshake(address, distributed)
    with client:
        yield client


def _handshake(address: str, distributed):
    """Dask's Client of `address`, once the server there has said, within CONNECT_SECONDS,
    that it is a Dask scheduler (Dask's "identity" call, on a connection of our own in an
    event loop of our own, cancelled at the deadline): a server that answers but is no
    scheduler (an HTTP server, a proxy) keeps Dask's own Client waiting for ever, or feeds
    it a frame length of exabytes (numpy's MemoryError)."""
    import asyncio

    async def identity() -> object:
        comm = await distributed.comm.connect(address, timeout=CONNECT_SECONDS)
        try:
            await comm.write({"op": "identity", "reply": True})
            return await comm.read()
        finally:
            comm.abort()

    try:
        answer = asyncio.run(asyncio.wait_for(identity(), CONNECT_SECONDS))
    except Exception as exc:  # noqa: BLE001 - Dask raises OSError, TimeoutError, ValueError, MemoryError here
        said = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise ClusterError(f"did not answer as a Dask scheduler within {CONNECT_SECONDS:g} s ({said})",
                           address=address) from None
    if not isinstance(answer, dict) or answer.get("type") != "Scheduler":
        raise ClusterError(f"answered, but not as a Dask scheduler (its identity: {str(answer)[:120]})",
                           address=address)
    return distributed.Client(address, timeout=f"{CONNECT_SECONDS}s")


def _host_port(address: str) -> tuple[str, int]:
    """(host, port) of "tcp://host:port" (or "host:port"); a ClusterError for anything else."""
    scheme, sep, rest = address.partition("://")
    if not sep:
        scheme, rest = "tcp", address
    host, _, port = rest.rpartition(":")
    host = host.strip("[]")
    if scheme not in _SCHEMES or not host or not port.isdigit() or not 0 < int(port) < 65536 or "/" in rest:
        raise ClusterError(f"{address!r} is not a scheduler address: write tcp://HOST:PORT, e.g. "
                           "tcp://127.0.0.1:8786 (schemes: " + ", ".join(_SCHEMES) + ")", address=address)
    return host, int(port)


#: The most worker processes a LocalCluster starts, per core of this machine: more only queue
#: for the cores, and each holds its own mechanism and Python (about 100 MB).
WORKERS_PER_CORE = 4


def checked_workers(workers: object) -> int:
    """`workers` as a number of local worker processes: a whole number from 0 (this process)
    to WORKERS_PER_CORE x the machine's cores, else an OptionError naming both (a count of
    1e11 started processes until the run was killed).

    A scheduler's address takes its workers from the cluster behind it, whatever this is."""
    import operator

    most = WORKERS_PER_CORE * (os.cpu_count() or 1)
    try:
        count = None if isinstance(workers, bool) else operator.index(workers)  # an int, numpy's too
    except TypeError:
        count = None
    if count is None or not 0 <= count <= most:
        raise OptionError(f"workers = {workers!r}: give a whole number of worker processes from 0 (this process) "
                          f"to {most} ({WORKERS_PER_CORE} per core of this machine's {os.cpu_count() or 1}), or "
                          "a running scheduler's address for more", option="workers", value=workers)
    return count


def local_cluster(workers: int, **options):
    """A LocalCluster of `workers` processes of one thread each on 127.0.0.1, its workers
    quiet (QUIET_WORKERS); `options` go to LocalCluster (e.g. silence_logs)."""
    import dask

    checked_workers(workers)
    distributed = require_dask()
    with dask.config.set(QUIET_WORKERS):  # a worker process takes the config it is started with
        return distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                        dashboard_address="127.0.0.1:0", host="127.0.0.1", **options)


def _serial(spec: StudySpec, batches: list[Batch], progress: Callable[[Batch], None] | None = None) -> list:
    results = []
    for batch in batches:
        results.append(solve_batch(spec, batch))
        if progress:
            progress(batch)
    return results


def scheduler_address(option: str | None) -> str | None:
    """The scheduler asked: the option, else $DASK_SCHEDULER_ADDRESS, else None (a LocalCluster)."""
    return option or os.environ.get("DASK_SCHEDULER_ADDRESS") or None


def _gathered(client, spec: StudySpec, batches: list[Batch], progress, distributed,
              address: str) -> list[BatchResult]:
    """The batches' results in batch order; the scheduler lost on the way is a ClusterError
    (the batches' own errors pass as they are)."""
    results: list[BatchResult | None] = [None] * len(batches)
    with lost_as_cluster_error(address, lambda: f"{sum(r is not None for r in results)} of {len(batches)} batches"):
        futures = client.map(solve_batch, [spec] * len(batches), batches, pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        for future in distributed.as_completed(futures):
            i = index[future.key]
            results[i] = future.result()
            if progress:
                progress(batches[i])
    return results


@contextmanager
def lost_as_cluster_error(address: str, done: Callable[[], str]) -> Iterator[None]:
    """Dask's errors for a scheduler or connection gone away, inside the block, as one
    ClusterError naming `address` and how far the run got (`done()`); pinmech's own errors
    and a task's own failure pass as they are."""
    try:
        yield
    except PinmechError:
        raise
    except Exception as exc:  # noqa: BLE001 - sorted by _lost: Dask's losses, else the task's own error
        if not _lost(exc):
            raise
        said = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise ClusterError(f"lost during the run after {done()} ({type(exc).__name__}: {said}); nothing was written",
                           address=address) from exc


def _lost(error: BaseException) -> bool:
    """Whether `error` says the scheduler or the connection to it went away (not a batch's failure)."""
    import asyncio
    import concurrent.futures

    module = type(error).__module__
    return (isinstance(error, (OSError, TimeoutError, asyncio.CancelledError, concurrent.futures.CancelledError))
            or module.startswith(("distributed", "tornado")))
