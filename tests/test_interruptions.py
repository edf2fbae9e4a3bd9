"""Interrupted commands leave nothing partial: SIGINT, SIGTERM and SIGKILL sent to the real command.

Each case starts ``python -m tmem ...`` in its own session, waits for a
moment (right after the start; while it simulates, shown by its progress bar
on a pseudo-terminal; while it writes, shown by its temporary name appearing;
while a sweep has saved rows), sends the signal and checks that the
destination is as it was or complete, never partial.  After SIGKILL, which no
process can handle, the next run of the same command must complete and
remove what the killed one left.  Each case is one process start (about 5 s,
mostly imports; the compiled code comes from Numba's cache, warmed by the
fixtures).
"""

import json
import os
import re
import select
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import psutil
import pytest
from dask.distributed import Client, LocalCluster
from typer.testing import CliRunner

from tmem.cli.main import app
from tmem.sweep import loads_sweep, run_sweep

ROOT = Path(__file__).parent.parent
SIGNALS = {"SIGINT": signal.SIGINT, "SIGTERM": signal.SIGTERM, "SIGKILL": signal.SIGKILL}
# The repulsion example, long: a few seconds of simulation behind a progress bar, then a few MB to write.
#: Long enough (3e7 steps, about 3 s on a quiet machine once compiled) that its progress bar, shown
#: after a second, is caught short of the end; recorded as often as the 60 s example, so that writing
#: takes as long.
LONG_RUN = (ROOT / "examples" / "repulsion.toml").read_text().replace("duration = 60.0", "duration = 3000.0").replace(
    "record_every = 100 ", "record_every = 500 "
)
SWEEP = """
name = "encounters"
base = "fig7"
cases = 20
seed = 5
batch = 1
[set]
"simulation.dt" = 0.0002
"simulation.duration" = 40.0
[grid]
"interaction.function" = ["switching", "improved"]
[random]
"agents.0.position" = { uniform = [45, 70] }
"agents.0.velocity" = { uniform = [-4, -1] }
"agents.1.velocity" = { uniform = [1, 4] }
"""
N_SWEEP_CASES = 40


def partials(folder: Path, name: str) -> list[str]:
    """Hidden entries of ``folder`` named after ``name``: temporary outputs (this tmem's or an earlier one's)."""
    return sorted(n for n in os.listdir(folder) if n.startswith(f".{name}."))


def being_written(folder: Path, name: str) -> bool:
    """Whether a temporary output named after ``name`` is being written: its directory locked and renamed to
    its partial name.  A kill in the microseconds before (``.NAME.tmem-starting-*`` made, its lock file not
    yet written) leaves that directory, which no later command can tell from one being made
    (:mod:`tmem.files.outputs.names`): the tests kill while the output is written."""
    return any(".tmem-partial-" in n for n in partials(folder, name))


class Command:
    """``python -m tmem ARGS`` in a session of its own, its output on a pseudo-terminal (progress bars show).

    With ``terminal=False`` its output goes to a pipe instead: no progress bar, only the lines it says.
    """

    def __init__(self, *args, cwd: Path, terminal: bool = True):
        env = {**os.environ, "PYTHONPATH": str(ROOT / "src"), "TERM": "xterm", "COLUMNS": "100"}
        self.master, slave = os.openpty() if terminal else os.pipe()
        self.process = subprocess.Popen(
            [sys.executable, "-m", "tmem", *map(str, args)],
            stdin=subprocess.DEVNULL, stdout=slave, stderr=slave, cwd=cwd, env=env, start_new_session=True,
        )  # fmt: skip
        os.close(slave)
        self.started = time.monotonic()
        self.output = b""

    def _read(self) -> None:
        while select.select([self.master], [], [], 0)[0]:
            try:
                chunk = os.read(self.master, 65536)
            except OSError:  # the terminal closed with the process
                return
            if not chunk:
                return
            self.output += chunk

    def wait_for(self, condition, timeout: float = 60) -> bool:
        """Wait until ``condition()`` holds (True) or the process ends first (False)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            self._read()
            if condition():
                return True
            if self.process.poll() is not None:
                return False
            time.sleep(0.005)
        raise AssertionError(f"nothing happened in {timeout} s: {self.output[-500:]!r}")

    def send(self, signum: int) -> None:
        # Ctrl-C reaches the terminal's whole process group; kill(1) and a killer reach one process.
        if signum == signal.SIGINT:
            os.killpg(self.process.pid, signum)
        else:
            self.process.send_signal(signum)

    def finish(self, timeout: float = 60) -> tuple[int, str]:
        try:
            code = self.process.wait(timeout)
        finally:
            self._read()
            try:
                os.killpg(self.process.pid, signal.SIGKILL)  # anything it started
            except ProcessLookupError:
                pass
            self.process.wait()
            os.close(self.master)
        return code, self.output.decode(errors="replace")


def _progress(output: bytes) -> int:
    """The latest percentage the progress bar showed in ``output``; 100 before it shows any (a loaded
    machine may read the output late, so the first "%" alone does not say that the run still simulates)."""
    shown = re.findall(rb"(\d+)%", output)
    return int(shown[-1]) if shown else 100


def moment(command: Command, when: str, writing) -> bool:
    """Wait for the moment ``when``; False if the command ended first."""
    if when == "start":
        return command.wait_for(lambda: time.monotonic() - command.started > 0.2)
    if when == "simulating":  # the progress bar's latest figure well short of the end: still simulating
        return command.wait_for(lambda: _progress(command.output) < 90 and not writing())
    return command.wait_for(writing)


def listed_files(out: Path) -> list[str]:
    return json.loads((out / ".tmem-output.json").read_text())["files"]


def snapshot(directory: Path) -> dict:
    return {str(p.relative_to(directory)): p.read_bytes() for p in sorted(directory.rglob("*")) if p.is_file()}


def check_exit(code: int, output: str, signum: int, when: str) -> None:
    if signum == signal.SIGKILL:
        assert code == -signal.SIGKILL
    elif when != "start":  # before the command installs its handlers, Python's defaults act
        assert code == 130, output
        assert "Traceback" not in output, output


# --- tmem run


@pytest.fixture(scope="module")
def long_run(tmp_path_factory):
    """The long scenario, and an earlier complete output of it (also warms Numba's cache)."""
    folder = tmp_path_factory.mktemp("long")
    scenario = folder / "long.toml"
    scenario.write_text(LONG_RUN)
    previous = folder / "previous"
    result = CliRunner().invoke(app, ["run", str(scenario), "--out", str(previous)])
    assert result.exit_code == 0, result.output
    return scenario, previous


@pytest.mark.parametrize("when", ["start", "simulating", "writing"])
@pytest.mark.parametrize("name", SIGNALS)
def test_interrupted_run_leaves_the_earlier_output_or_a_whole_new_one(long_run, tmp_path, name, when):
    scenario, previous = long_run
    signum = SIGNALS[name]
    out = tmp_path / "out"
    shutil.copytree(previous, out)
    before = snapshot(out)
    command = Command("run", scenario, "--out", out, cwd=tmp_path)
    reached = moment(command, when, lambda: being_written(tmp_path, "out"))
    if reached:
        command.send(signum)
    code, output = command.finish()
    assert reached, f"the run ended before the moment {when!r}: {output}"
    check_exit(code, output, signum, when)
    after = snapshot(out)
    assert after == before or sorted(p for p in after if p != ".tmem-output.json") == listed_files(out)
    if signum != signal.SIGKILL:
        assert partials(tmp_path, "out") == [], output
        return
    # The next run completes and removes what the killed one left.
    result = CliRunner().invoke(app, ["run", str(scenario), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert partials(tmp_path, "out") == []
    assert sorted(p.name for p in out.iterdir() if p.name != ".tmem-output.json") == listed_files(out)


def test_a_signal_after_the_command_is_done_keeps_its_exit_status():
    """Ctrl-C or SIGTERM arriving while Python shuts down, the output already in place, is not the exit status."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        script = (
            "import os, sys\n"
            "from tmem.cli.main import main\n"
            "sys.argv = ['tmem', '--help']\n"
            f"try:\n    main()\nfinally:\n    os.kill(os.getpid(), {int(signum)})\n"
        )
        env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
        done = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, (signum, done.returncode, done.stderr[-500:])
        assert "Traceback" not in done.stderr


# --- tmem animate


@pytest.fixture(scope="module")
def run_2d(pair_2d_factory):
    scenario = pair_2d_factory(40.0, 10)
    folder = scenario.parent
    result = CliRunner().invoke(app, ["run", str(scenario), "--out", str(folder / "run")])
    assert result.exit_code == 0, result.output
    return folder / "run"


@pytest.mark.parametrize("when", ["start", "writing"])
@pytest.mark.parametrize("name", SIGNALS)
def test_interrupted_animate_leaves_no_partial_gif(run_2d, tmp_path, name, when):
    signum = SIGNALS[name]
    run = tmp_path / "run"
    shutil.copytree(run_2d, run)
    gif = tmp_path / "run.gif"  # beside the run, by default
    command = Command("animate", run, "--max-frames", "40", cwd=tmp_path)
    reached = moment(command, when, lambda: being_written(tmp_path, "run.gif") or gif.exists())
    if reached:
        command.send(signum)
    code, output = command.finish()
    assert reached, f"animate ended before the moment {when!r}: {output}"
    check_exit(code, output, signum, when)
    # The signal may come as the finished file is being renamed into place: then it is whole.
    assert not gif.exists() or gif.read_bytes().endswith(b";"), "a partial GIF"  # ";": a GIF's trailer
    if signum != signal.SIGKILL:
        assert partials(tmp_path, "run.gif") == []
        return
    result = CliRunner().invoke(app, ["animate", str(run), "--max-frames", "3"])
    assert result.exit_code == 0, result.output
    assert gif.exists() and partials(tmp_path, "run.gif") == []


def test_an_interrupt_a_library_turns_into_its_own_error_still_ends_the_command_as_interrupted(
    run_2d, tmp_path, monkeypatch, capfd
):
    """Ctrl-C while Matplotlib's compiled code calls back into Python: the KeyboardInterrupt raised
    there comes out as Matplotlib's ValueError ("Invalid affine transformation matrix"). The command
    still ends as interrupted, status 130, not as a failed one with that error."""
    import tmem.figures.animate
    import tmem.files.outputs.signals as signals
    from tmem.cli.main import main

    def drawn_as_matplotlib_may(*args, **kwargs):
        try:
            signal.raise_signal(signal.SIGINT)
        except KeyboardInterrupt:
            raise ValueError("Invalid affine transformation matrix") from None

    monkeypatch.setattr(tmem.figures.animate, "animate", drawn_as_matplotlib_may)
    monkeypatch.setattr(signals, "_received", [])
    monkeypatch.setattr(sys, "argv", ["tmem", "animate", str(run_2d)])
    handlers = {signum: signal.getsignal(signum) for signum in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    try:
        with pytest.raises(SystemExit) as ended:
            main()
    finally:
        for signum, handler in handlers.items():  # main() leaves them ignored, as the process ends there
            signal.signal(signum, handler)
    output = capfd.readouterr()
    assert ended.value.code == 130, output
    assert "affine" not in output.out + output.err and "error" not in output.out + output.err


# --- tmem plot


def whole_png(data: bytes) -> bool:
    return data.startswith(b"\x89PNG\r\n\x1a\n") and data.endswith(b"IEND\xaeB`\x82")


@pytest.mark.parametrize("name", ["SIGTERM", "SIGKILL"])  # Ctrl-C: tests/test_plot_command.py, in the process
def test_interrupted_plot_leaves_the_old_figures_or_whole_new_ones(run_2d, tmp_path, name):
    signum = SIGNALS[name]
    run = tmp_path / "run"
    shutil.copytree(run_2d, run)
    figures = sorted(p.name for p in run.glob("*.png"))
    before = {figure: (run / figure).read_bytes() for figure in figures}  # tmem's own: plot may replace them
    command = Command("plot", run, cwd=tmp_path)
    reached = moment(command, "writing", lambda: being_written(run, "figures"))
    if reached:
        command.send(signum)
    code, output = command.finish()
    assert reached, f"plot ended before it wrote: {output}"
    check_exit(code, output, signum, "writing")
    after = [(run / figure).read_bytes() for figure in figures]
    # The same run draws the same bytes: old or new, each figure is whole and as tmem drew it.
    assert all(whole_png(a) and a == before[f] for f, a in zip(figures, after)), output
    if signum != signal.SIGKILL:
        assert partials(run, "figures") == []
        return
    result = CliRunner().invoke(app, ["plot", str(run)])
    assert result.exit_code == 0, result.output
    assert partials(run, "figures") == [] and all(whole_png((run / f).read_bytes()) for f in figures)


# --- tmem sweep


@pytest.fixture(scope="module")
def cluster():
    """A cluster the sweeps connect to by address, warm (its workers' imports done once)."""
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster:
        with Client(cluster) as client:
            client.run(lambda: __import__("tmem.sweep.tasks"))
        yield cluster.scheduler_address


@pytest.fixture
def sweep_file(tmp_path):
    path = tmp_path / "encounters.toml"
    path.write_text(SWEEP)
    return path


def saved_rows(out: Path) -> bool:
    return (out / "parts").is_dir() and any(p.name.startswith("part-") for p in (out / "parts").iterdir())


def sweep_leftovers(out: Path) -> list[str]:
    folders = [out, out / "parts"] if (out / "parts").is_dir() else [out]
    return sorted(n for folder in folders for n in os.listdir(folder) if ".tmem-partial-" in n or n.endswith(".tmp"))


@pytest.mark.parametrize("when", ["start", "saving rows"])
@pytest.mark.parametrize("name", SIGNALS)
def test_interrupted_sweep_resumes_and_finishes(cluster, sweep_file, tmp_path, name, when):
    signum = SIGNALS[name]
    out = tmp_path / "out"
    command = Command("sweep", sweep_file, "--out", out, "--scheduler", cluster, cwd=tmp_path)
    reached = moment(command, when, lambda: saved_rows(out))
    if reached:
        command.send(signum)
    code, output = command.finish()
    assert reached, f"the sweep ended before the moment {when!r}: {output}"
    check_exit(code, output, signum, when)
    if signum != signal.SIGKILL and when != "start":
        assert "run the same command again" in output
    assert not (out / "results.parquet").exists()
    if signum != signal.SIGKILL:
        assert not out.exists() or sweep_leftovers(out) == []
    sweep = loads_sweep(SWEEP, source=str(sweep_file))
    outcome = run_sweep(sweep, out, scheduler=cluster)
    assert list(outcome.table["case"]) == list(range(N_SWEEP_CASES))
    assert sweep_leftovers(out) == [] and not (out / ".tmem-lock").exists()


def test_two_sweeps_into_one_directory_at_once(cluster, sweep_file, tmp_path):
    """The second is refused in one line naming the first; once the first is killed, it runs."""
    out = tmp_path / "out"
    first = Command("sweep", sweep_file, "--out", out, "--scheduler", cluster, cwd=tmp_path)
    try:
        assert first.wait_for(lambda: saved_rows(out)), first.output
        result = CliRunner().invoke(app, ["sweep", str(sweep_file), "--out", str(out), "--scheduler", cluster])
        assert result.exit_code == 2, result.output
        assert result.stderr.count("\n") == 1 and "Traceback" not in result.stderr
        assert f"another `tmem sweep` (process {first.process.pid}) is writing to it" in result.stderr
        first.send(signal.SIGKILL)
    finally:
        first.finish()
    result = CliRunner().invoke(app, ["sweep", str(sweep_file), "--out", str(out), "--scheduler", cluster])
    assert result.exit_code == 0, result.output
    assert list(pd.read_parquet(out / "results.parquet")["case"]) == list(range(N_SWEEP_CASES))


# --- tmem sweep on its own local cluster: Ctrl-C says one line, a killed worker nothing

# 200 cases, 8 a task: half a minute or more on two workers.  (Tasks of a second or more make it
# likelier that a killed worker held a result not yet gathered, which Dask then says it could not.)
LOCAL_SWEEP = SWEEP.replace("cases = 20", "cases = 100").replace("batch = 1", "batch = 8")
LOCAL_CASES = 200
INTERRUPTED = re.compile(rf"interrupted: [0-9]+ of {LOCAL_CASES} cases saved; run the same command again to go on\n")


def workers_of(command: Command) -> list[psutil.Process]:
    """The worker processes of the command's local cluster (started by multiprocessing's spawn)."""
    try:
        children = psutil.Process(command.process.pid).children()
        return [p for p in children if "spawn_main" in " ".join(p.cmdline())]
    except psutil.Error:
        return []


def catches_sigint(pid: int) -> bool:
    """Whether process ``pid`` has a handler for SIGINT (neither the default nor ignored)."""
    status = Path(f"/proc/{pid}/status").read_text()
    caught = int(next(line.split()[1] for line in status.splitlines() if line.startswith("SigCgt:")), 16)
    return bool(caught & (1 << (signal.SIGINT - 1)))


#: Moments of a sweep on a local cluster: its workers exist and start up (no output folder yet),
#: its tasks run (no rows yet), rows are saved.
LOCAL_MOMENTS = {
    "workers starting": lambda c, out: len(workers_of(c)) == 2 and catches_sigint(c.process.pid) and not out.exists(),
    "tasks running": lambda c, out: (out / "parts").is_dir() and not saved_rows(out),
    "saving rows": lambda c, out: saved_rows(out),
}


@pytest.fixture
def local_sweep(tmp_path):
    path = tmp_path / "encounters.toml"
    path.write_text(LOCAL_SWEEP)
    return path


@pytest.mark.parametrize("reaching", ["the group", "the command alone"])
@pytest.mark.parametrize("when", LOCAL_MOMENTS)
def test_ctrl_c_on_a_local_sweep_says_one_line(local_sweep, tmp_path, when, reaching):
    """Neither lost while the workers start, nor followed by Dask's tracebacks as the cluster shuts down."""
    out = tmp_path / "out"
    command = Command("sweep", local_sweep, "--out", out, "--workers", 2, cwd=tmp_path, terminal=False)
    reached = command.wait_for(lambda: LOCAL_MOMENTS[when](command, out), timeout=120)
    if reached:  # Ctrl-C reaches the terminal's whole group; kill -INT the command alone
        (os.killpg if reaching == "the group" else os.kill)(command.process.pid, signal.SIGINT)
    code, output = command.finish()
    assert reached, f"the sweep ended before the moment {when!r}: {output}"
    assert code == 130, output
    assert INTERRUPTED.fullmatch(output), output
    assert not (out / "results.parquet").exists() and (not out.exists() or sweep_leftovers(out) == [])


def test_a_killed_worker_of_a_local_sweep_says_nothing(local_sweep, tmp_path):
    """Dask runs the lost tasks again; its messages about recovering ("Couldn't gather keys") are not shown."""
    out = tmp_path / "out"
    command = Command("sweep", local_sweep, "--out", out, "--workers", 2, cwd=tmp_path, terminal=False)
    try:
        assert command.wait_for(lambda: saved_rows(out), timeout=120), command.output
        workers_of(command)[0].kill()
    finally:
        code, output = command.finish(timeout=600)
    assert code == 0, output
    assert output.startswith(f"{LOCAL_CASES} cases ({LOCAL_CASES} run now, 0 failed) in "), output
    for word in ("ERROR", "CRITICAL", "WARNING", "Traceback", "Couldn't gather"):
        assert word not in output, output
    assert list(pd.read_parquet(out / "results.parquet")["case"]) == list(range(LOCAL_CASES))
