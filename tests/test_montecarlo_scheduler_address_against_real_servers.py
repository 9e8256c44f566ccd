"""`attitude montecarlo --scheduler ADDRESS` says in one line what answered at an
address that is not a Dask scheduler, within seconds, before a Client exists.

Against real servers on this machine: a real `distributed` scheduler (its own
address passes; its dashboard's, the address users see in their browser, used to
hang with no message), Python's own HTTP server (used to end with "out of memory"
and a traceback 20 s later), a server of another protocol (an SSH banner), a port
where nothing listens, and one that accepts and says nothing.
"""

import http.server
import logging
import socket
import threading
from urllib.parse import urlparse

import pytest
from montecarlo_scenarios import write_spinner

import attitude.jobs.cluster as cluster
from attitude.base.errors import InputError
from attitude.cli.main import main


@pytest.fixture(scope="module")
def dask_scheduler():
    """A real scheduler (no workers) with its web server, the dashboard's (its pages need
    bokeh; its server answers without): (its address, the dashboard's as tcp://)."""
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=0,
        processes=False,
        protocol="tcp",
        host="127.0.0.1",
        dashboard_address="127.0.0.1:0",
        silence_logs=logging.CRITICAL,
    ) as local:
        dashboard = urlparse(local.dashboard_link)
        yield local.scheduler_address, f"tcp://{dashboard.hostname}:{dashboard.port}"


def _serve(handle) -> tuple[str, threading.Thread, socket.socket]:
    """A TCP server on 127.0.0.1 calling ``handle(connection)`` for each connection."""
    server = socket.create_server(("127.0.0.1", 0))

    def loop():
        while True:
            try:
                connection, _ = server.accept()
            except OSError:
                return
            with connection:
                handle(connection)

    thread = threading.Thread(target=loop, daemon=True)
    thread.start()
    return f"tcp://127.0.0.1:{server.getsockname()[1]}", thread, server


@pytest.fixture
def http_server():
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), http.server.SimpleHTTPRequestHandler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"tcp://127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()


def _refusal(address: str) -> str:
    with pytest.raises(InputError) as caught:
        cluster.probe_scheduler(address)
    error = caught.value
    assert error.key == "--scheduler" and error.value == address
    line = str(error)
    assert line.startswith(f"--scheduler {address}: ") and "\n" not in line
    return line


def test_a_real_scheduler_passes_and_its_dashboard_is_named(dask_scheduler):
    address, dashboard = dask_scheduler
    cluster.probe_scheduler(address)  # a Dask handshake: accepted
    line = _refusal(dashboard)
    assert "a web server answered (HTTP/1.1 " in line and "dashboard" in line, line


def test_the_dashboards_port_on_the_command_line_is_one_line_and_exit_2(
    dask_scheduler, tmp_path, capsys
):
    _, dashboard = dask_scheduler
    scenario = write_spinner(tmp_path)
    out = tmp_path / "out"
    code = main(["montecarlo", str(scenario), "--out", str(out), "--scheduler", dashboard])
    err = capsys.readouterr().err.splitlines()
    assert code == 2
    errors = [line for line in err if not line.startswith("[")]
    assert errors == [errors[0]] and errors[0].startswith(
        f"attitude: error: spinner.toml: --scheduler {dashboard}: a web server answered"
    ), err
    assert not out.exists()


def test_a_plain_http_server_is_named(http_server):
    line = _refusal(http_server)
    assert "a web server answered (HTTP/1.0 200 OK)" in line, line


def test_another_protocol_is_named():
    address, _, server = _serve(lambda c: c.sendall(b"SSH-2.0-OpenSSH_9.6\r\n"))
    try:
        line = _refusal(address)
    finally:
        server.close()
    assert "another protocol answered, not a Dask scheduler: 'SSH-2.0-OpenSSH_9.6'" in line


def test_a_port_where_nothing_listens_is_refused():
    with socket.create_server(("127.0.0.1", 0)) as taken:
        port = taken.getsockname()[1]
    line = _refusal(f"tcp://127.0.0.1:{port}")
    assert "connection refused: nothing listens on that port" in line


def test_a_server_that_says_nothing_is_refused_within_the_timeout(monkeypatch):
    monkeypatch.setattr(cluster, "_FIRST_WORDS_S", 0.2)
    silent = threading.Event()
    address, _, server = _serve(lambda c: silent.wait(5.0))
    try:
        with pytest.raises(InputError, match=r"said nothing a Dask scheduler says within 0\.7 s"):
            cluster.probe_scheduler(address, timeout_s=0.5)
    finally:
        silent.set()
        server.close()
