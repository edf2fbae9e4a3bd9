"""Output directories (tmem.files.outputs): which may be replaced, what is refused, leftovers, the sweep's lock."""

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import pandas as pd
import pytest
from dask.distributed import LocalCluster
from typer.testing import CliRunner

from tmem.cli.main import app
from tmem.files.outputs import MANIFEST, OutputError, lock, partial_name
from tmem.files.outputs.names import WRITING
from tmem.sweep import loads_sweep, run_sweep

EXAMPLES = Path(__file__).parent.parent / "examples"
SRC = Path(__file__).parent.parent / "src"
SWEEP = """
name = "small"
base = "fig7"
cases = 3
seed = 5
[set]
"simulation.dt" = 0.01
"simulation.duration" = 40.0
[random]
"agents.0.position" = { uniform = [45, 70] }
"""


@pytest.fixture
def runner():
    return CliRunner()


def invoke(runner, *args):
    result = runner.invoke(app, [str(a) for a in args])
    return result.exit_code, result.stderr, result.output


def one_line_refusal(code, stderr):
    assert code == 2, stderr
    assert stderr.count("\n") == 1 and stderr.startswith("error: "), stderr
    assert "Traceback" not in stderr


def snapshot(directory: Path) -> dict:
    return {str(p.relative_to(directory)): p.read_bytes() for p in sorted(directory.rglob("*")) if p.is_file()}


def dead_pid() -> int:
    process = subprocess.Popen([sys.executable, "-c", "pass"])
    process.wait()
    return process.pid


@pytest.fixture(scope="module")
def pair_2d(pair_2d_factory):
    """Two agents in the plane, short and coarse: a run of a second or so that `animate` can draw."""
    return pair_2d_factory(20.0, 100)


@pytest.fixture(scope="module")
def threads():
    with LocalCluster(n_workers=1, processes=False, dashboard_address=":0") as cluster:
        yield cluster.scheduler_address


# --- Item 1: a directory is replaced only when it holds an output of the same command, and nothing else


def fake_output(directory: Path, command: str, files: dict[str, str], listed=True) -> Path:
    for name, text in files.items():
        (directory / name).parent.mkdir(parents=True, exist_ok=True)
        (directory / name).write_text(text)
    manifest = {"command": command, "tmem": "0.1.0", "files": sorted(files) if listed else None}
    (directory / MANIFEST).write_text(json.dumps(manifest))
    return directory


def test_run_refuses_a_paper_output_and_says_what_is_there(runner, tmp_path):
    files = {f"fig{n}/{f}": "x" for n in (5, 7, 9) for f in ("summary.json", "trajectory.nc", "velocity.png")}
    paper = fake_output(tmp_path / "paper", "paper", {**files, "report.md": "# report"})
    before = snapshot(paper)
    code, stderr, _ = invoke(runner, "run", EXAMPLES / "repulsion.toml", "--out", paper)
    one_line_refusal(code, stderr)
    assert "holds a `tmem paper` output (fig5/, fig7/, fig9/, report.md)" in stderr
    assert "choose another --out or remove it" in stderr
    assert snapshot(paper) == before


def test_rerunning_run_keeps_an_animation_written_into_its_directory(runner, tmp_path, pair_2d):
    out = tmp_path / "pair"
    assert invoke(runner, "run", pair_2d, "--out", out)[0] == 0
    code, stderr, _ = invoke(runner, "animate", out, "--max-frames", "5", "--out", out / "animation.gif")
    assert code == 0, stderr
    before = snapshot(out)
    code, stderr, _ = invoke(runner, "run", pair_2d, "--out", out)
    one_line_refusal(code, stderr)
    assert "holds a `tmem run` output and files it did not write (animation.gif)" in stderr
    assert snapshot(out) == before


def test_derived_files_go_beside_the_run_and_the_run_can_be_written_again(runner, tmp_path, pair_2d):
    """`tmem view`, `tmem animate` and `tmem export` by default: beside the run directory, never in it."""
    out = tmp_path / "pair"
    assert invoke(runner, "run", pair_2d, "--out", out)[0] == 0
    run_files = sorted(p.name for p in out.iterdir())
    for args in (("animate", out, "--max-frames", "3"), ("export", out, "--to", "mcap"), ("export", out, "--to", "csv"),
                 ("view", out)):  # fmt: skip
        code, stderr, _ = invoke(runner, *args)
        assert code == 0, stderr
    assert sorted(p.name for p in out.iterdir()) == run_files
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pair", "pair-crazyswarm", "pair.gif", "pair.html", "pair.mcap"]
    code, stderr, _ = invoke(runner, "run", pair_2d, "--out", out)
    assert code == 0, stderr
    for args in (("animate", out, "--max-frames", "4"), ("export", out, "--to", "csv")):  # their own, replaced
        code, stderr, _ = invoke(runner, *args)
        assert code == 0, stderr


#: A command that writes an output directory, the file of it a user edits, and the command again.
EDITED = {
    "run": (lambda run, out: ("run", run["scenario"], "--out", out), "summary.json"),
    "plot --out": (lambda run, out: ("plot", run["out"], "--out", out), "velocity.png"),
    "export --to csv": (lambda run, out: ("export", run["out"], "--to", "csv", "--out", out), "agent1.csv"),
}


@pytest.fixture(scope="module")
def written_run(pair_2d, tmp_path_factory):
    out = tmp_path_factory.mktemp("written") / "pair"
    assert invoke(CliRunner(), "run", pair_2d, "--out", out)[0] == 0
    return {"scenario": pair_2d, "out": out}


@pytest.mark.parametrize("command", EDITED)
def test_a_file_changed_since_tmem_wrote_it_is_never_replaced(runner, tmp_path, written_run, command):
    args, name = EDITED[command]
    out = tmp_path / "out"
    assert invoke(runner, *args(written_run, out))[0] == 0
    with open(out / name, "ab") as f:
        f.write(b"\nmy notes")
    before = snapshot(out)
    code, stderr, _ = invoke(runner, *args(written_run, out))
    one_line_refusal(code, stderr)
    assert f"whose files were changed since it wrote them ({name})" in stderr
    assert snapshot(out) == before
    (out / name).unlink()  # once it is gone, nothing of the user's is lost: the output is written again
    assert invoke(runner, *args(written_run, out))[0] == 0


def test_plot_keeps_a_figure_the_user_marked(runner, tmp_path, written_run):
    run = tmp_path / "pair"
    shutil.copytree(written_run["out"], run)
    with open(run / "velocity.png", "ab") as f:
        f.write(b"annotated")
    before = snapshot(run)
    code, stderr, _ = invoke(runner, "plot", run)
    one_line_refusal(code, stderr)
    assert f"{run / 'velocity.png'}: was changed since tmem wrote it" in stderr
    assert snapshot(run) == before


def legacy(out: Path) -> None:
    """Make ``out``'s manifest one of an earlier tmem: no digests."""
    manifest = json.loads((out / MANIFEST).read_text())
    del manifest["sha256"]
    (out / MANIFEST).write_text(json.dumps(manifest))


def test_an_earlier_tmems_output_is_replaced_only_while_no_file_is_newer_than_its_manifest(runner, tmp_path, written_run):
    out = tmp_path / "pair"
    shutil.copytree(written_run["out"], out)
    legacy(out)
    assert invoke(runner, "run", written_run["scenario"], "--out", out)[0] == 0
    assert "sha256" in json.loads((out / MANIFEST).read_text())  # written again, with digests
    legacy(out)
    time.sleep(0.01)
    (out / "summary.json").write_text((out / "summary.json").read_text() + "\n")  # changed after the manifest
    code, stderr, _ = invoke(runner, "run", written_run["scenario"], "--out", out)
    one_line_refusal(code, stderr)
    assert "were changed since it wrote them (summary.json)" in stderr
    code, stderr, _ = invoke(runner, "plot", out)  # the summary is no figure: plot may draw, and lists what is still tmem's
    assert code == 0, stderr
    manifest = json.loads((out / MANIFEST).read_text())
    assert "summary.json" not in manifest["files"] and "velocity.png" in manifest["sha256"]


@pytest.mark.parametrize("command", ["run", "paper"])
def test_a_sweep_directory_is_named_as_one(runner, tmp_path, command):
    sweep = fake_output(tmp_path / "sweep", "sweep", {"sweep.toml": SWEEP, "sweep.json": "{}", "summary.md": ""}, False)
    args = ("run", EXAMPLES / "repulsion.toml") if command == "run" else ("paper",)
    code, stderr, _ = invoke(runner, *args, "--out", sweep)
    one_line_refusal(code, stderr)
    assert "holds a `tmem sweep` output (summary.md, sweep.json, sweep.toml)" in stderr
    assert "did not write" not in stderr


def test_a_sweep_refuses_a_run_output(runner, tmp_path, threads):
    out = fake_output(tmp_path / "r", "run", {"summary.json": "{}", "trajectory.nc": ""})
    sweep_file = tmp_path / "s.toml"
    sweep_file.write_text(SWEEP)
    code, stderr, _ = invoke(runner, "sweep", sweep_file, "--out", out, "--scheduler", threads)
    one_line_refusal(code, stderr)
    assert "holds a `tmem run` output (summary.json, trajectory.nc)" in stderr


def test_output_with_an_unlisted_file_or_a_broken_manifest_is_refused(runner, tmp_path):
    out = fake_output(tmp_path / "r", "run", {"summary.json": "{}"})
    (out / "notes").mkdir()
    (out / "notes" / "mine.txt").write_text("precious")
    code, stderr, _ = invoke(runner, "run", EXAMPLES / "repulsion.toml", "--out", out)
    one_line_refusal(code, stderr)
    assert "(notes/mine.txt)" in stderr
    shutil.rmtree(out / "notes")
    (out / MANIFEST).write_text("{not json")
    code, stderr, _ = invoke(runner, "run", EXAMPLES / "repulsion.toml", "--out", out)
    one_line_refusal(code, stderr)
    assert ".tmem-output.json cannot be read" in stderr


def test_current_directory_is_refused_by_run_and_sweep_alike(runner, tmp_path, monkeypatch):
    """Item 8: `tmem sweep --out .` was allowed while `tmem run --out .` was refused."""
    sweep_file = tmp_path / "s.toml"
    sweep_file.write_text(SWEEP)
    here = tmp_path / "here"
    here.mkdir()
    monkeypatch.chdir(here)
    for args in (("run", EXAMPLES / "repulsion.toml"), ("sweep", sweep_file, "--scheduler", "nope://x")):
        for out in (".", here.parent):
            code, stderr, _ = invoke(runner, *args, "--out", out)
            one_line_refusal(code, stderr)
            assert "is the current directory or contains it" in stderr
    assert list(here.iterdir()) == []


def test_animate_replaces_only_a_file_it_wrote(runner, tmp_path, pair_2d):
    out = tmp_path / "pair"
    assert invoke(runner, "run", pair_2d, "--out", out)[0] == 0
    mine = tmp_path / "mine.gif"
    mine.write_bytes(b"GIF89a a picture of my own")
    code, stderr, _ = invoke(runner, "animate", out, "--out", mine, "--max-frames", "3")
    one_line_refusal(code, stderr)
    assert "exists and was not written by tmem animate" in stderr
    assert mine.read_bytes() == b"GIF89a a picture of my own"
    ours = tmp_path / "ours.gif"
    for frames in ("3", "4"):
        code, stderr, _ = invoke(runner, "animate", out, "--out", ours, "--max-frames", frames)
        assert code == 0, stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine.gif", "ours.gif", "pair"]


# --- Item 4: what a killed process left is removed by the next run; nothing else is


def killed_writers_partial(folder: Path, name: str, pid: int | None = None) -> Path:
    """A temporary directory as a killed tmem leaves it: its lock file there, held by nobody."""
    path = folder / f".{name}.tmem-partial-{pid or dead_pid()}-0123abcd"
    path.mkdir()
    (path / WRITING).write_text(json.dumps({"pid": pid or 1}))
    (path / name).write_bytes(b"\0" * 1000)
    return path


HOLD_PARTIAL = """
import fcntl, json, os, sys, time
path = sys.argv[1]
os.makedirs(path)
fd = os.open(os.path.join(path, ".tmem-writing"), os.O_RDWR | os.O_CREAT)
fcntl.flock(fd, fcntl.LOCK_EX)
os.write(fd, json.dumps({"pid": int(sys.argv[2]), "host": "elsewhere"}).encode())
print("held", flush=True)
time.sleep(120)
"""


def test_run_removes_what_a_killed_run_left_and_nothing_else(runner, tmp_path):
    out = tmp_path / "out"
    gone = killed_writers_partial(tmp_path, "out")
    kept = [
        tmp_path / f".out.tmem-partial-{dead_pid()}-0123abce",  # no lock file: an earlier tmem's, or being made
        tmp_path / ".out.tmem-partial-notes",  # not tmem's pattern
        tmp_path / ".out.k2j4h5g6",  # an earlier tmem's name, indistinguishable from a user's
        tmp_path / f"out.tmem-partial-{dead_pid()}-0123abcd",  # not hidden
    ]
    for path in kept:
        path.mkdir()
    (kept[-1] / WRITING).write_text("")
    code, stderr, _ = invoke(runner, "run", EXAMPLES / "repulsion.toml", "--out", out)
    assert code == 0, stderr
    assert not gone.exists()
    assert all(path.is_dir() for path in kept)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out.tmem-partial-") and p not in kept]


def test_animate_removes_what_a_writer_killed_while_making_its_temporary_directory_left(runner, tmp_path, pair_2d):
    """Killed between making ``.NAME.tmem-starting-…`` and renaming it: its lock file holds its process
    id, locked by nobody, so it is removed; one whose lock file is still empty is being locked this
    instant by a live writer, and is kept."""
    out = tmp_path / "pair"
    assert invoke(runner, "run", pair_2d, "--out", out)[0] == 0
    gone = tmp_path / f".pair.gif.tmem-starting-{dead_pid()}-0123abcd"
    being_made = tmp_path / f".pair.gif.tmem-starting-{dead_pid()}-0123abce"
    for path, text in ((gone, json.dumps({"pid": 1})), (being_made, "")):
        path.mkdir()
        (path / WRITING).write_text(text)
    code, stderr, _ = invoke(runner, "animate", out, "--max-frames", "3")
    assert code == 0, stderr
    assert not gone.exists() and (being_made / WRITING).is_file() and (tmp_path / "pair.gif").exists()


def test_a_writer_in_another_pid_namespace_is_left_to_write(runner, tmp_path):
    """Its process id means nothing here (a container, `unshare --pid`): its lock says it writes."""
    foreign = dead_pid()  # no such process in this namespace
    writing = tmp_path / f".out.tmem-partial-{foreign}-89abcdef"
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    holder = subprocess.Popen([sys.executable, "-c", HOLD_PARTIAL, str(writing), str(foreign)], stdout=subprocess.PIPE, text=True, env=env)
    try:
        assert holder.stdout.readline() == "held\n"
        code, stderr, _ = invoke(runner, "run", EXAMPLES / "repulsion.toml", "--out", tmp_path / "out")
        assert code == 0, stderr
        assert (writing / WRITING).is_file(), "another writer's work was removed"
    finally:
        holder.kill()
        holder.wait()
    # its writer gone, the next writer into the folder removes it
    code, stderr, _ = invoke(runner, "run", EXAMPLES / "repulsion.toml", "--out", tmp_path / "out")
    assert code == 0, stderr
    assert not writing.exists()


def test_animate_removes_a_killed_animations_partial_file(runner, tmp_path, pair_2d):
    out = tmp_path / "pair"
    assert invoke(runner, "run", pair_2d, "--out", out)[0] == 0
    partial = killed_writers_partial(tmp_path, "pair.gif")
    code, stderr, _ = invoke(runner, "animate", out, "--max-frames", "3")
    assert code == 0, stderr
    assert not partial.exists() and (tmp_path / "pair.gif").exists()


def test_sweep_removes_temporary_results_of_a_killed_finish(tmp_path, threads):
    sweep = loads_sweep(SWEEP, source="s.toml")
    out = tmp_path / "out"
    run_sweep(sweep, out, scheduler=threads)
    leftovers = [
        out / ".results.parquet.1a2b3c4d.tmp",  # as an earlier tmem named it
        out / f".results.parquet.tmem-partial-{dead_pid()}-1a2b3c4d.parquet",
        out / f".summary.md.tmem-partial-{dead_pid()}-1a2b3c4d.md",
    ]
    for path in leftovers:
        path.write_bytes(b"PAR1 cut short")
    again = run_sweep(sweep, out, scheduler=threads)
    assert again.ran == 0
    assert not [p for p in leftovers if p.exists()]
    assert sorted(p.name for p in out.iterdir() if p.name.startswith(".")) == [MANIFEST]


def test_a_sweep_keeps_a_report_the_user_changed(tmp_path, threads):
    sweep = loads_sweep(SWEEP, source="s.toml")
    out = tmp_path / "out"
    run_sweep(sweep, out, scheduler=threads)
    assert run_sweep(sweep, out, scheduler=threads).ran == 0  # its own report, as written: replaced
    with open(out / "summary.md", "a") as f:
        f.write("my conclusions\n")
    before = snapshot(out)
    with pytest.raises(OutputError, match=r"whose files were changed since it wrote them \(summary.md\)"):
        run_sweep(sweep, out, scheduler=threads)
    assert snapshot(out) == before


# --- Item 4: a sweep killed between writing sweep.toml and sweep.json


def test_a_directory_holding_only_sweep_toml_is_taken_up(tmp_path, threads):
    """An earlier tmem killed between the two files left this; it must not be unusable forever."""
    sweep = loads_sweep(SWEEP, source="s.toml")
    out = tmp_path / "out"
    (out / "parts").mkdir(parents=True)
    (out / "sweep.toml").write_text(sweep.text)
    outcome = run_sweep(sweep, out, scheduler=threads)
    assert list(outcome.table["case"]) == [0, 1, 2]
    assert json.loads((out / "sweep.json").read_text())["fingerprint"] == sweep.fingerprint


def test_a_sweep_interrupted_while_making_its_directory_leaves_nothing(tmp_path, threads, monkeypatch):
    sweep = loads_sweep(SWEEP, source="s.toml")
    out = tmp_path / "new" / "out"
    real = Path.write_text

    def killed_after_sweep_toml(self, *args, **kwargs):
        written = real(self, *args, **kwargs)
        if "sweep.toml" in self.name:
            raise KeyboardInterrupt
        return written

    monkeypatch.setattr(Path, "write_text", killed_after_sweep_toml)
    with pytest.raises(KeyboardInterrupt):
        run_sweep(sweep, out, scheduler=threads)
    monkeypatch.setattr(Path, "write_text", real)
    assert list(tmp_path.iterdir()) == []
    assert len(run_sweep(sweep, out, scheduler=threads).table) == 3


# --- Item 7: two sweeps into one directory at once


HOLD_LOCK = """
import sys, time
from pathlib import Path
from tmem.files import outputs
with getattr(outputs, sys.argv[2])(Path(sys.argv[1]), "sweep"):
    print("held", flush=True)
    time.sleep(60)
"""


@contextmanager
def held(path: Path, how: str = "lock"):
    """Another process holding the sweep's lock of ``path`` (``how``: ``lock``, inside; ``lock_beside``)."""
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    holder = subprocess.Popen([sys.executable, "-c", HOLD_LOCK, str(path), how], stdout=subprocess.PIPE, text=True, env=env)
    try:
        assert holder.stdout.readline() == "held\n"
        yield holder
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()


def test_a_second_sweep_into_a_directory_in_use_is_refused_until_the_first_is_gone(tmp_path, threads):
    sweep_file = tmp_path / "s.toml"
    sweep_file.write_text(SWEEP)
    out = tmp_path / "out"
    sweep = loads_sweep(SWEEP, source=str(sweep_file))
    run_sweep(sweep, out, scheduler=threads)
    (out / "results.parquet").unlink()  # as if unfinished: every case to run again
    with held(out) as holder:
        code, stderr, _ = invoke(CliRunner(), "sweep", sweep_file, "--out", out, "--scheduler", threads)
        one_line_refusal(code, stderr)
        assert f"another `tmem sweep` (process {holder.pid}) is writing to it" in stderr
        assert not (out / "results.parquet").exists()
    # the holder was killed: its lock went with it
    assert run_sweep(sweep, out, scheduler=threads).ran == 3
    assert not (out / ".tmem-lock").exists()


def test_a_sweep_takes_its_lock_before_it_looks_at_the_directory(tmp_path, threads):
    """Held by a sweep that has not made its directory yet: a second is refused, and makes nothing."""
    sweep_file = tmp_path / "s.toml"
    sweep_file.write_text(SWEEP)
    out = tmp_path / "out"
    with held(out, "lock_beside") as holder:
        code, stderr, _ = invoke(CliRunner(), "sweep", sweep_file, "--out", out, "--scheduler", threads)
        one_line_refusal(code, stderr)
        assert f"another `tmem sweep` (process {holder.pid}) is writing to it" in stderr
        assert not out.exists()
    assert run_sweep(loads_sweep(SWEEP, source=str(sweep_file)), out, scheduler=threads).ran == 3
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "s.toml"]  # the lock beside is gone with its holder


@pytest.fixture(scope="module")
def tcp_threads():
    """A cluster in this process that other processes reach by TCP."""
    with LocalCluster(n_workers=1, processes=False, protocol="tcp", dashboard_address=":0") as cluster:
        yield cluster.scheduler_address


def test_two_sweeps_started_at_once_run_each_case_once(tmp_path, tcp_threads):
    sweep_file = tmp_path / "s.toml"
    sweep_file.write_text(SWEEP)
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    args = [sys.executable, "-m", "tmem", "sweep", str(sweep_file), "--out", str(out), "--scheduler", tcp_threads]
    both = [subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env) for _ in range(2)]
    ran = 0
    for process in both:
        stdout, stderr = process.communicate(timeout=300)
        if process.returncode == 0:
            ran += int(stdout.split("(")[1].split(" run now")[0])
        else:
            one_line_refusal(process.returncode, stderr)
            assert "is writing to it" in stderr
    assert ran == 3  # every case once, by one or the other
    assert list(pd.read_parquet(out / "results.parquet")["case"]) == [0, 1, 2]


def test_lock_refuses_a_second_holder_in_this_process_too(tmp_path):
    with lock(tmp_path, "sweep"):
        assert json.loads((tmp_path / ".tmem-lock").read_text())["pid"] == os.getpid()
        with pytest.raises(OutputError, match=rf"process {os.getpid()}\) is writing to it"):
            with lock(tmp_path, "sweep"):
                pass
    with lock(tmp_path, "sweep"):
        pass


# --- Item 8: a --scheduler error leaves no skeleton


def test_a_scheduler_error_writes_nothing(runner, tmp_path):
    sweep_file = tmp_path / "s.toml"
    sweep_file.write_text(SWEEP)
    start = time.monotonic()
    code, stderr, _ = invoke(runner, "sweep", sweep_file, "--out", tmp_path / "new" / "out", "--scheduler", "nope://x")
    one_line_refusal(code, stderr)
    assert "--scheduler nope://x: cannot connect" in stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]
    assert time.monotonic() - start < 10


def test_partial_names_stay_short_and_keep_the_suffix():
    name = partial_name("a" * 255 + ".gif", ".gif")
    assert len(name.encode()) < 255 and name.endswith(".gif") and f"tmem-partial-{os.getpid()}-" in name


@pytest.mark.parametrize("out", ["x" * 300, "new/" + "y" * 256 + "/out"])
def test_a_name_too_long_is_refused_before_anything_runs(runner, tmp_path, pair_2d, monkeypatch, out):
    monkeypatch.chdir(tmp_path)
    code, stderr, _ = invoke(runner, "run", EXAMPLES / "repulsion.toml", "--out", out)
    one_line_refusal(code, stderr)
    assert "has a name longer than 255 bytes" in stderr
    run = tmp_path / "pair"
    assert invoke(runner, "run", pair_2d, "--out", run)[0] == 0
    code, stderr, _ = invoke(runner, "animate", run, "--out", out + ".gif")
    one_line_refusal(code, stderr)
    assert "has a name longer than 255 bytes" in stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pair"]
