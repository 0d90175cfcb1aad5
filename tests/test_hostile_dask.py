"""Dask under attack: a bad or unreachable scheduler address fails in seconds with one line
(a ClusterError, exit 2), a worker killed mid-run changes no bit of the results, the
scheduler lost mid-run is one line and no output file, and every socket pinmech's
LocalCluster opens (scheduler, workers, nannies, the dashboard) listens on 127.0.0.1 only.
Each test starts its own small LocalCluster on 127.0.0.1 and closes it.
"""

from __future__ import annotations

import os
import signal
import socket
import time
from pathlib import Path

import numpy as np
import pytest

from pinmech.cli import main
from pinmech.design.cluster import CONNECT_SECONDS, batch_runner, local_cluster, solve_batch
from pinmech.design.study.file import load_study
from pinmech.design.study.tolerance import batches
from pinmech.exceptions import ClusterError

distributed = pytest.importorskip("distributed")
psutil = pytest.importorskip("psutil")
ROOT = Path(__file__).resolve().parents[1]
STUDY = ROOT / "models" / "studies" / "four_bar_tolerance.toml"
SYNTHESIS = ROOT / "models" / "synthesis" / "four_bar_path.toml"


def _spec(samples: int = 120, batch: int = 10, steps: int = 19):
    spec = load_study(STUDY)
    return spec.__class__(**{**spec.__dict__, "samples": samples, "batch": batch, "steps": steps})


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize("address, said", [
    ("nonsense", "not a scheduler address"),
    ("http://127.0.0.1:8787", "not a scheduler address"),
    ("tcp://127.0.0.1", "not a scheduler address"),
    ("tcp://127.0.0.1:99999", "not a scheduler address"),
    ("tcp://no.such.host.invalid:8786", "cannot reach"),
    ("tcp://127.0.0.1:{free}", "cannot reach"),
    ("tcp://{http}", "did not answer as a Dask scheduler"),
])
@pytest.mark.parametrize("command", ["study", "synth"])
def test_a_bad_or_unreachable_scheduler_is_one_line_in_seconds(address, said, command, capsys):
    """Before: 20 s of waiting ('Timed out trying to connect'), or a traceback (a ValueError
    for 'nonsense', numpy's 3 EiB MemoryError for a server that is no scheduler); `synth`
    had its own connection, without the study's checks, until round 4's last stop."""
    import http.server
    import threading

    class Quiet(http.server.BaseHTTPRequestHandler):
        def log_message(self, *args) -> None:  # its log on stderr is not pinmech's line
            pass

    server = http.server.HTTPServer(("127.0.0.1", 0), Quiet)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        address = address.format(free=_free_port(), http=f"127.0.0.1:{server.server_address[1]}")
        began = time.monotonic()
        argv = [str(STUDY), "--quiet"] if command == "study" else [str(SYNTHESIS)]
        code = main([command, *argv, "--scheduler", address])
        seconds = time.monotonic() - began
    finally:
        server.shutdown()
    err = capsys.readouterr().err.strip()
    assert code == ClusterError.exit_code and len(err.splitlines()) == 1 and said in err, err
    assert "Traceback" not in err and seconds < CONNECT_SECONDS + 5, seconds


def _listening(pids: set[int]) -> list[tuple[int, str, int]]:
    """(pid, address, port) of every listening TCP socket of these processes."""
    return [(c.pid, c.laddr.ip, c.laddr.port) for c in psutil.net_connections(kind="tcp")
            if c.status == psutil.CONN_LISTEN and c.pid in pids]


def test_every_socket_of_a_local_cluster_listens_on_localhost_only():
    """Scheduler, dashboard, workers and nannies: 127.0.0.1, never 0.0.0.0 or ::."""
    me = psutil.Process()
    with local_cluster(2, silence_logs=50) as cluster, distributed.Client(cluster) as client:
        client.run(os.getpid)  # the workers are up
        pids = {me.pid, *(p.pid for p in me.children(recursive=True))}
        sockets = _listening(pids)
        assert cluster.dashboard_link  # the dashboard is one of them
    assert len({pid for pid, _, _ in sockets}) >= 3, sockets  # this process and 2 worker processes
    assert {ip for _, ip, _ in sockets} == {"127.0.0.1"}, sockets


def test_a_worker_killed_mid_run_changes_no_bit():
    """Batches are drawn from the seed and their index: a batch lost with its worker is run
    again elsewhere and gives the same numbers as in one process."""
    spec = _spec()
    todo = batches(spec.samples, spec.batch)
    serial = [solve_batch(spec, b) for b in todo]
    killed = []

    with local_cluster(2, silence_logs=50) as cluster, distributed.Client(cluster) as client:
        pids = list(client.run(os.getpid).values())

        def kill_one(batch) -> None:
            if not killed:
                os.kill(pids[0], signal.SIGKILL)
                killed.append(pids[0])

        with batch_runner(scheduler=cluster.scheduler_address) as run:
            results = run(spec, todo, kill_one)
    assert killed
    for a, b in zip(serial, results):
        np.testing.assert_array_equal(a.y, b.y)  # bit for bit: the same arithmetic, in the same order
        np.testing.assert_array_equal(a.p, b.p)


def test_the_scheduler_lost_mid_run_is_one_line_and_no_output(tmp_path):
    """The scheduler stops after the first batch: a ClusterError within seconds, no file."""
    spec = _spec(samples=400, batch=5, steps=37)
    todo = batches(spec.samples, spec.batch)
    cluster = local_cluster(1, silence_logs=50)
    began = []
    try:
        with batch_runner(scheduler=cluster.scheduler_address) as run:
            def stop_scheduler(batch) -> None:
                if not began:
                    began.append(time.monotonic())
                    cluster.close()

            with pytest.raises(ClusterError, match="lost"):
                run(spec, todo, stop_scheduler)
    finally:
        cluster.close()
    assert time.monotonic() - began[0] < CONNECT_SECONDS + 20


@pytest.mark.parametrize("workers", ["100000000000", "-1", str(4 * (os.cpu_count() or 1) + 1)])
@pytest.mark.parametrize("command", ["study", "synth"])
def test_a_worker_count_the_machine_cannot_hold_is_refused_before_anything_starts(workers, command, capsys):
    """--workers 100000000000 started a LocalCluster of that many processes (killed after a
    minute of forking); now refused in one line, before the file is read: at most four
    worker processes a core (cluster.WORKERS_PER_CORE), a scheduler's address for more."""
    with pytest.raises(SystemExit) as stop:
        main([command, str(STUDY if command == "study" else SYNTHESIS), "--workers", workers])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and f"--workers: {workers}: give a whole number of worker processes" in err


@pytest.mark.parametrize("workers", [10**11, -1, 2.5, True, "2"])
def test_the_api_refuses_the_same_worker_counts(workers):
    import pinmech
    from pinmech.exceptions import OptionError

    for run, path in ((pinmech.study, STUDY), (pinmech.synthesise, SYNTHESIS)):
        with pytest.raises(OptionError, match=r"workers = .*: give a whole number of worker processes from 0"):
            run(path, workers=workers)


def test_a_synthesis_whose_scheduler_is_lost_is_a_cluster_error_naming_how_far_it_got():
    """The population's evaluation on a cluster gone away: one ClusterError ("lost during the
    run after N candidates"), as a study's, not Dask's CommClosedError or a 20 s timeout."""
    from pinmech.design.synthesis.file import load_synthesis
    from pinmech.design.synthesis.search import PopulationMap

    spec = load_synthesis(SYNTHESIS)
    cluster = local_cluster(1, silence_logs=50)
    client = distributed.Client(cluster)
    try:
        mapper = PopulationMap(spec, client, 1, cluster.scheduler_address)
        rows = np.tile((spec.lower + spec.upper) / 2, (4, 1))
        assert len(mapper(None, rows)) == 4
        cluster.close()
        began = time.monotonic()
        with pytest.raises(ClusterError, match="lost during the run after 4 candidates"):
            mapper(None, rows)
        assert time.monotonic() - began < CONNECT_SECONDS + 30
    finally:
        client.close()
        cluster.close()
