"""Output directories (tmem.files.outputs): which may be replaced, what is refused, leftovers, the sweep's lock."""

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
from dask.distributed import LocalCluster
from typer.testing import CliRunner

from tmem.cli.main import app
from tmem.files.outputs import MANIFEST, OutputError, lock, partial_name
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


def test_rerunning_run_keeps_the_animation_written_into_its_directory(runner, tmp_path, pair_2d):
    out = tmp_path / "pair"
    assert invoke(runner, "run", pair_2d, "--out", out)[0] == 0
    code, stderr, _ = invoke(runner, "animate", out, "--max-frames", "5")
    assert code == 0, stderr
    before = snapshot(out)
    code, stderr, _ = invoke(runner, "run", pair_2d, "--out", out)
    one_line_refusal(code, stderr)
    assert "holds a `tmem run` output and files it did not write (animation.gif)" in stderr
    assert snapshot(out) == before
    # animate, run again, replaces its own animation
    code, stderr, _ = invoke(runner, "animate", out, "--max-frames", "4")
    assert code == 0, stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pair"]


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


def test_run_removes_what_a_killed_run_left_and_nothing_else(runner, tmp_path):
    out = tmp_path / "out"
    gone = tmp_path / f".out.tmem-partial-{dead_pid()}-0123abcd"
    gone.mkdir()
    (gone / "trajectory.nc").write_bytes(b"\0" * 1000)
    kept = [
        tmp_path / f".out.tmem-partial-{os.getpid()}-0123abcd",  # a process still running (this one)
        tmp_path / ".out.tmem-partial-notes",  # not tmem's pattern
        tmp_path / ".out.k2j4h5g6",  # an earlier tmem's name, indistinguishable from a user's
        tmp_path / f"out.tmem-partial-{dead_pid()}-0123abcd",  # not hidden
    ]
    for path in kept:
        path.mkdir()
    code, stderr, _ = invoke(runner, "run", EXAMPLES / "repulsion.toml", "--out", out)
    assert code == 0, stderr
    assert not gone.exists()
    assert all(path.is_dir() for path in kept)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out.tmem-partial-") and p not in kept]


def test_animate_removes_a_killed_animations_partial_file(runner, tmp_path, pair_2d):
    out = tmp_path / "pair"
    assert invoke(runner, "run", pair_2d, "--out", out)[0] == 0
    partial = out / f".animation.gif.tmem-partial-{dead_pid()}-00ff00ff.gif"
    partial.write_bytes(b"GIF89a cut short")
    code, stderr, _ = invoke(runner, "animate", out, "--max-frames", "3")
    assert code == 0, stderr
    assert not partial.exists() and (out / "animation.gif").exists()


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
from tmem.files.outputs import lock
with lock(Path(sys.argv[1]), "sweep"):
    print("held", flush=True)
    time.sleep(60)
"""


def test_a_second_sweep_into_a_directory_in_use_is_refused_until_the_first_is_gone(tmp_path, threads):
    sweep_file = tmp_path / "s.toml"
    sweep_file.write_text(SWEEP)
    out = tmp_path / "out"
    sweep = loads_sweep(SWEEP, source=str(sweep_file))
    run_sweep(sweep, out, scheduler=threads)
    (out / "results.parquet").unlink()  # as if unfinished: every case to run again
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    holder = subprocess.Popen([sys.executable, "-c", HOLD_LOCK, str(out)], stdout=subprocess.PIPE, text=True, env=env)
    try:
        assert holder.stdout.readline() == "held\n"
        code, stderr, _ = invoke(CliRunner(), "sweep", sweep_file, "--out", out, "--scheduler", threads)
        one_line_refusal(code, stderr)
        assert f"another `tmem sweep` (process {holder.pid}) is writing to it" in stderr
        assert not (out / "results.parquet").exists()
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    # the holder was killed: its lock went with it
    assert run_sweep(sweep, out, scheduler=threads).ran == 3
    assert not (out / ".tmem-lock").exists()


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
