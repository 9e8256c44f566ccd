"""The local Dask cluster leaves no process, port or file behind: closed normally, or
by Ctrl-C in the middle of a job.

The processes and ports are read from the system (psutil): the worker processes this
process started, the ports they and this process listen on.  After the cluster is
closed, every one of those processes has ended and nothing listens on those ports.
Ctrl-C is sent as a terminal sends it, to the whole process group of an `attitude
montecarlo` run: exit status 130, one line on stderr, no process of its session left,
no output folder.
"""

import os
import signal
import socket
import subprocess
import sys
import time

import psutil
from montecarlo_scenarios import write_spinner
from signal_dispositions import defaults

from attitude.jobs.cluster import connect


def _listening_ports(processes) -> set[int]:
    ports = set()
    for process in processes:
        for connection in process.net_connections(kind="tcp"):
            if connection.status == psutil.CONN_LISTEN:
                ports.add(connection.laddr.port)
    return ports


def _port_is_free(port: int) -> bool:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # TIME_WAIT is not a listener
        try:
            probe.bind(("127.0.0.1", port))
        except OSError:
            return False
    return True


def _is_resource_tracker(process) -> bool:
    """multiprocessing's resource tracker: one per Python process, started by its first
    child process and ended with it (not the cluster's)."""
    try:
        return "resource_tracker" in " ".join(process.cmdline())
    except psutil.NoSuchProcess:
        return False


def test_local_cluster_of_2_workers_leaves_no_process_or_port():
    me = psutil.Process()
    before = {p.pid for p in me.children(recursive=True)}
    with connect(workers=2) as client:
        assert len(client.scheduler_info()["workers"]) == 2
        started = [
            p
            for p in me.children(recursive=True)
            if p.pid not in before and not _is_resource_tracker(p)
        ]
        assert len(started) >= 2  # the worker processes
        ports = _listening_ports([me, *started])
        assert len(ports) >= 3  # the scheduler and each worker
        assert not any(_port_is_free(port) for port in ports)
    _, alive = psutil.wait_procs(started, timeout=15)
    assert not alive
    assert not ports & _listening_ports([me])
    assert all(_port_is_free(port) for port in ports)


def _session(sid: int) -> list[psutil.Process]:
    found = []
    for process in psutil.process_iter():
        try:
            if os.getsid(process.pid) == sid and process.status() != psutil.STATUS_ZOMBIE:
                found.append(process)
        except (ProcessLookupError, PermissionError, psutil.NoSuchProcess):
            continue
    return found


def test_ctrl_c_closes_the_cluster_and_leaves_nothing(tmp_path):
    user = tmp_path / "user"
    user.mkdir()
    scenario = write_spinner(user, samples=400)
    out = user / "results"
    run = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "attitude",
            "montecarlo",
            str(scenario),
            "--out",
            str(out),
            "--workers",
            "2",
            "--batch-size",
            "2",
        ],
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # its own process group, as a terminal's foreground job
        preexec_fn=defaults,  # not the ignored SIGINT of a `pytest &`
    )
    lines = []
    try:
        for line in run.stderr:  # the progress bar's first line: the samples are running
            lines.append(line)
            if "/400 samples" in line:
                break
        workers = [p for p in _session(run.pid) if p.pid != run.pid]
        assert len(workers) >= 2
        os.killpg(run.pid, signal.SIGINT)
        rest = run.stderr.read().splitlines()
        assert run.wait(timeout=60) == 130
    finally:
        if run.poll() is None:
            os.killpg(run.pid, signal.SIGKILL)
    after = [line for line in rest if not line.startswith("[")]  # the bar may print again
    assert not any("Traceback" in line for line in lines + rest)
    deadline = time.monotonic() + 10
    while _session(run.pid) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert _session(run.pid) == []
    # Nothing, or only the samples finished before the Ctrl-C, in the job's checkpoint.
    if after == ["attitude: error: interrupted; nothing of this run was left behind"]:
        assert not out.exists()
    else:
        assert len(after) == 1 and after[0].startswith("attitude: error: interrupted; "), rest
        assert after[0].endswith(
            f"of 400 samples are kept in {out}/.attitude-checkpoint: the same command with "
            "--resume continues the job"
        ), rest
        assert sorted(p.name for p in out.iterdir()) == [".attitude-checkpoint"]
    assert sorted(p.name for p in user.iterdir()) in (["spinner.toml"], ["results", "spinner.toml"])


def test_ctrl_c_while_the_cluster_starts_stops_the_job(tmp_path):
    """A Ctrl-C during the local cluster's start used to be lost (SIGINT was ignored
    meanwhile, so that the workers would inherit it ignored) and the job ran to its
    end: it is delivered once the cluster exists, which is closed."""
    user = tmp_path / "user"
    user.mkdir()
    scenario = write_spinner(user, samples=40)
    out = user / "results"
    options = ["--out", str(out), "--workers", "2", "--batch-size", "2"]
    run = subprocess.Popen(
        [sys.executable, "-m", "attitude", "montecarlo", str(scenario), *options],
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=defaults,
    )
    lines = []
    try:
        for line in run.stderr:
            lines.append(line)
            if "starting a local Dask cluster" in line:
                break
        os.killpg(run.pid, signal.SIGINT)  # as a terminal sends it: the whole group
        rest = run.stderr.read().splitlines()
        assert run.wait(timeout=120) == 130, lines + rest
    finally:
        if run.poll() is None:
            os.killpg(run.pid, signal.SIGKILL)
    assert rest == ["attitude: error: interrupted; nothing of this run was left behind"], rest
    assert not any("samples" in line for line in lines)  # no sample ran
    deadline = time.monotonic() + 10
    while _session(run.pid) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert _session(run.pid) == []
    assert not out.exists()
    assert sorted(p.name for p in user.iterdir()) == ["spinner.toml"]
