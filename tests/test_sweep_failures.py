"""A sweep meets what is not its own: a damaged file of rows, a --scheduler that is no Dask scheduler, bad options."""

import io
import logging
import socket
import socketserver
import threading
import time
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq
import pytest
from dask.distributed import LocalCluster
from typer.testing import CliRunner

from tmem.cli.main import app
from tmem.sweep import SweepError, loads_sweep, run_sweep
from tmem.sweep.cluster import DaskLog, check_workers, dask_client
from tmem.sweep.store import ResultStore
from tmem.sweep.tasks import run_chunk

SWEEP = """
name = "small"
base = "fig7"
cases = 6
seed = 5
[set]
"simulation.dt" = 0.01
"simulation.duration" = 40.0
[random]
"agents.0.position" = { uniform = [45, 70] }
"""


@pytest.fixture(scope="module")
def cluster():
    with LocalCluster(n_workers=1, processes=False, dashboard_address=":0") as cluster:
        yield cluster


@pytest.fixture(scope="module")
def threads(cluster):
    return cluster.scheduler_address


@pytest.fixture
def sweep_file(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(SWEEP)
    return path


def invoke(*args):
    result = CliRunner().invoke(app, [str(a) for a in args])
    return result.exit_code, result.stderr


def one_line_refusal(code, stderr):
    assert code == 2, stderr
    assert stderr.count("\n") == 1 and stderr.startswith("error: "), stderr
    assert "Traceback" not in stderr


# --- A damaged file of rows is set aside, its cases run again


def two_parts(out: Path, sweep) -> list[Path]:
    """Write the sweep's first 4 cases as two parts (2 cases each), as an interrupted sweep leaves them."""
    metrics = tuple(sweep.spec.metrics)
    cases = sweep.cases()
    store = ResultStore.check(out, sweep)
    with store.opened():
        store.add(run_chunk(sweep.base, cases[0:2], metrics))
        store.add(run_chunk(sweep.base, cases[2:4], metrics))
    parts = sorted((out / "parts").glob("part-*.parquet"))
    assert len(parts) == 2
    return parts


def truncate(path: Path) -> None:
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])


def flip_a_bit_in_the_data(path: Path) -> None:
    """Flip one bit of the ``case`` column's last data byte: only the page checksum tells."""
    column = pq.ParquetFile(path).metadata.row_group(0).column(0)
    assert column.path_in_schema == "case"
    start = column.dictionary_page_offset or column.data_page_offset
    data = bytearray(path.read_bytes())
    data[start + column.total_compressed_size - 1] ^= 0x01
    path.write_bytes(bytes(data))


def garbage(path: Path) -> None:
    path.write_bytes(b"PAR1" + b"\x00garbage" * 100 + b"PAR1")


def other_cases(path: Path) -> None:
    """A readable part whose case numbers are not the sweep's (as if copied from a larger one)."""
    frame = pd.read_parquet(path)
    frame["case"] += 1000
    frame.to_parquet(path, index=False)


@pytest.mark.parametrize("damage", [truncate, flip_a_bit_in_the_data, garbage, other_cases])
def test_a_damaged_part_is_set_aside_and_its_cases_run_again(threads, tmp_path, damage):
    sweep = loads_sweep(SWEEP, source="small.toml")
    out = tmp_path / "out"
    damaged, whole = two_parts(out, sweep)
    damage(damaged)
    kept = damaged.read_bytes()
    lines = []
    outcome = run_sweep(sweep, out, scheduler=threads, notify=lines.append)
    assert list(outcome.table["case"]) == list(range(6))
    assert outcome.ran == 4  # the 2 cases of the damaged part and the 2 never run
    assert outcome.table["error"].isna().all()
    aside = out / (damaged.name + ".corrupt")
    assert aside.read_bytes() == kept  # set aside as it was, never deleted
    assert len(lines) == 1 and "\n" not in lines[0]
    assert f"parts/{damaged.name}" in lines[0] and f"set aside as {aside.name}" in lines[0]
    assert not (out / "parts").exists()
    # The next run finds everything done, and leaves the set-aside file alone.
    again = run_sweep(sweep, out, scheduler=threads, notify=lines.append)
    assert again.ran == 0 and len(lines) == 1 and aside.read_bytes() == kept


def test_a_damaged_results_file_is_set_aside_and_the_sweep_runs_again(threads, tmp_path, sweep_file):
    out = tmp_path / "out"
    code, stderr = invoke("sweep", sweep_file, "--out", out, "--scheduler", threads)
    assert code == 0, stderr
    truncate(out / "results.parquet")
    kept = (out / "results.parquet").read_bytes()
    code, stderr = invoke("sweep", sweep_file, "--out", out, "--scheduler", threads)
    assert code == 0, stderr
    assert stderr.count("\n") == 1 and stderr.startswith("warning: results.parquet in ") and "Traceback" not in stderr
    assert "set aside as results.parquet.corrupt, its cases run again" in stderr
    assert (out / "results.parquet.corrupt").read_bytes() == kept
    assert list(pd.read_parquet(out / "results.parquet")["case"]) == list(range(6))
    # Damaged again: the earlier set-aside file is kept, the new one takes the next free name.
    truncate(out / "results.parquet")
    code, stderr = invoke("sweep", sweep_file, "--out", out, "--scheduler", threads)
    assert code == 0, stderr
    assert (out / "results.parquet.corrupt").read_bytes() == kept and (out / "results.parquet.2.corrupt").exists()



# --- A --scheduler that is not a Dask scheduler is refused, in a bounded time, leaving nothing


class Garbage(socketserver.BaseRequestHandler):
    """Answers every connection with bytes that are not Dask's protocol, until it is closed."""

    def handle(self):
        try:
            for _ in range(1200):
                self.request.sendall(b"\xff\xfe not a dask scheduler \x00" * 64)
                time.sleep(0.05)
        except OSError:
            pass


class QuietWeb(SimpleHTTPRequestHandler):
    """A web server's answers, without its log lines on standard error."""

    def log_message(self, *args):
        pass


def serving(server) -> str:
    server.daemon_threads = True
    threading.Thread(target=server.serve_forever, daemon=True).start()
    host, port = server.server_address[:2]
    return f"tcp://{host}:{port}"


@pytest.fixture
def web_server():
    with ThreadingHTTPServer(("127.0.0.1", 0), QuietWeb) as server:
        yield serving(server)
        server.shutdown()


@pytest.fixture
def garbage_server():
    with socketserver.ThreadingTCPServer(("127.0.0.1", 0), Garbage) as server:
        yield serving(server)
        server.shutdown()


def closed_port() -> str:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return f"tcp://127.0.0.1:{s.getsockname()[1]}"


def sweep_at(address, tmp_path, sweep_file):
    """``tmem sweep --scheduler address``; fails the test if it has not ended after a minute (a hang)."""
    ended = {}

    def sweep():
        ended["code"], ended["stderr"] = invoke("sweep", sweep_file, "--out", tmp_path / "new" / "out", "--scheduler", address)

    thread = threading.Thread(target=sweep, daemon=True)
    thread.start()
    thread.join(60)
    assert not thread.is_alive(), f"tmem sweep --scheduler {address} hangs"
    return ended["code"], ended["stderr"]


@pytest.mark.parametrize(
    "server, why",
    [
        ("web_server", "nothing answered as a Dask scheduler within 2 s"),
        ("garbage_server", "what answers there is not a Dask scheduler"),
        ("worker", "what answers there is a Dask Worker, not a scheduler"),
        ("closed_port", "cannot connect (OSError: Timed out trying to connect to"),
    ],
)
def test_a_scheduler_that_is_not_one_is_refused_in_one_line(request, cluster, tmp_path, sweep_file, monkeypatch, server, why):
    monkeypatch.setattr("tmem.sweep.cluster.CONNECT_SECONDS", 2.0)  # the command's bound is 10 s; 2 s here
    if server == "worker":
        address = next(iter(cluster.scheduler_info["workers"]))
    elif server == "closed_port":
        address = closed_port()
    else:
        address = request.getfixturevalue(server)
    code, stderr = sweep_at(address, tmp_path, sweep_file)
    one_line_refusal(code, stderr)
    assert stderr.startswith(f"error: --scheduler {address}: {why}"), stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["small.toml"]  # no skeleton of a sweep folder


# --- Dask's log while a sweep runs: errors that are news, one line each; nothing of its recovery


@pytest.fixture
def dask_says():
    """Dask's log handled as in a command (distributed's set-up: one handler, on these loggers), into a string."""
    said = io.StringIO()
    handler = logging.StreamHandler(said)
    loggers = [logging.getLogger(name) for name in ("distributed", "distributed.client")]
    propagate = [logger.propagate for logger in loggers]
    for logger in loggers:
        logger.addHandler(handler)
        logger.propagate = False
    yield said
    for logger, before in zip(loggers, propagate):
        logger.removeHandler(handler)
        logger.propagate = before


def test_dask_errors_are_one_line_and_its_recovery_is_not_shown(threads, dask_says):
    with dask_client(threads, None):
        try:
            raise ConnectionError("the scheduler\nwent away")
        except ConnectionError:
            logging.getLogger("distributed.client").error("Failed to reconnect:\n  giving up", exc_info=True)
        logging.getLogger("distributed.scheduler").error("Couldn't gather keys: {'run_chunk-1': 'queued'}")
        logging.getLogger("distributed.scheduler").warning("Removing worker; rescheduling its tasks")
    said = dask_says.getvalue()
    assert said.count("\n") == 1 and "Traceback" not in said, said
    assert said == "Failed to reconnect: giving up\n", said
    handlers = logging.getLogger("distributed").handlers
    assert not any(isinstance(f, DaskLog) for h in handlers for f in h.filters)  # held only while the client is


def test_nothing_of_dask_is_shown_once_the_sweep_stops():
    log = DaskLog()
    record = logging.LogRecord("distributed.scheduler", logging.CRITICAL, "scheduler.py", 1, "Closed comm", (), None)
    assert log.filter(record)
    log.closing = True
    assert not log.filter(record)


# --- --workers: one line naming it


@pytest.mark.parametrize(
    "workers, why",
    [
        ("0", "must be at least 1"),
        ("-2", "must be at least 1"),
        ("two", "must be a whole number of worker processes"),
        ("1.5", "must be a whole number of worker processes"),
        ("100000", "more than 8 per core"),
    ],
)
def test_a_bad_workers_count_is_refused_in_one_line(tmp_path, sweep_file, workers, why):
    code, stderr = invoke("sweep", sweep_file, "--out", tmp_path / "out", "--workers", workers)
    one_line_refusal(code, stderr)
    assert stderr.startswith(f"error: --workers {workers}: {why}"), stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["small.toml"]


def test_workers_with_a_scheduler_is_refused(threads, tmp_path, sweep_file):
    code, stderr = invoke("sweep", sweep_file, "--out", tmp_path / "out", "--workers", "2", "--scheduler", threads)
    one_line_refusal(code, stderr)
    assert "--workers 2: is for the local cluster; with --scheduler" in stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["small.toml"]


def test_the_python_api_checks_workers_alike(tmp_path):
    sweep = loads_sweep(SWEEP, source="small.toml")
    with pytest.raises(SweepError, match="--workers 0: must be at least 1"):
        run_sweep(sweep, tmp_path / "out", workers=0)
    assert not (tmp_path / "out").exists()
    assert check_workers(None) is None and check_workers(3) == 3 and check_workers(" 2 ") == 2


def test_a_sweep_output_path_is_printed_as_written(threads, sweep_file, tmp_path, monkeypatch):
    """Rich markup in --out is text: the last line names the folder the rows went to."""
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(app, ["sweep", str(sweep_file), "--out", "[bold]y", "--scheduler", threads])
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines()[-1].endswith("written to [bold]y/results.parquet and [bold]y/summary.md")
    assert (tmp_path / "[bold]y" / "results.parquet").is_file()
