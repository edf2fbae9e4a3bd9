"""The bad-input battery, continued: outputs that are not regular files, usage errors, control characters.

Each case is given to the command line in this process and must end with exit status 2, exactly one
line of output starting ``error:``, no traceback, nothing read from what stands at ``--out`` (a FIFO
would block for ever: each case runs under a deadline) and nothing changed in its folder:

* every command that writes a file (``view``, ``animate``, ``export --to mcap``) x an ``--out`` that
  is a FIFO, ``/dev/full``, ``/dev/null``, a link to a file, a link to ``/dev/zero``, a folder;
* every command that writes a folder (``run``, ``plot``, ``export --to csv``, ``sweep``) x a FIFO,
  ``/dev/full``, ``/dev/null``, a link to a file;
* usage errors (an unknown command or option, a missing option or argument, text for a number): one
  line with the ``--help`` to read, never Typer's box;
* a path with a newline, an escape sequence, a carriage return or a bell, where ``--out`` or the
  run directory goes: the message escapes it, so that it cannot split the line, forge another or
  reach the terminal;
* what is read has a bound: a YAML "billion laughs" or a robot's name with a newline in a
  ``crazyflies.yaml``, a checkpoint whose arrays declare more than the file holds (its meta checked
  before any array is read), a run's ``summary.json`` that is a FIFO or too large;
* every writer onto a read-only file system (a real read-only mount where the machine allows one,
  and a rename refused with EROFS in this process): one line, no traceback from the clean-up.

``tests/test_bad_input_battery.py`` holds the scenario and sweep files' cases.
"""

from __future__ import annotations

import errno
import io
import json
import os
import shutil
import signal
import subprocess
import sys
import zipfile
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import tmem
from tmem.cli.main import app
from tmem.engine.checkpoint import FORMAT, checkpoint_path, fingerprint, made_by

EXAMPLES = Path(__file__).parent.parent / "examples"


@pytest.fixture
def runner():
    return CliRunner()


# -- outputs that are not regular files; usage errors; control characters in what a message names -----------


@pytest.fixture(scope="module")
def saved(pair_2d_factory):
    """A run written by `tmem run` (before the simulation is refused for the cases)."""
    scenario = pair_2d_factory(5.0, 100)
    out = scenario.parent / "run"
    assert CliRunner().invoke(app, ["run", str(scenario), "--out", str(out)]).exit_code == 0
    return {"scenario": str(scenario), "run": str(out), "sweep": str(EXAMPLES / "sweeps" / "encounters.toml")}


@contextmanager
def deadline(seconds: float):
    """Fail a case that blocks (reading a FIFO waits for a writer for ever) instead of hanging the suite."""
    def late(signum, frame):
        raise TimeoutError(f"still running after {seconds} s")

    previous = signal.signal(signal.SIGALRM, late)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def _fifo(d: Path, name: str) -> Path:
    os.mkfifo(d / name)
    return d / name


def _link(d: Path, name: str, to: Path) -> Path:
    (d / name).symlink_to(to)
    return d / name


#: What stands where an output goes, made in a folder ``d``.
NOT_A_FILE = {
    "a FIFO": (lambda d, suffix: _fifo(d, f"o{suffix}"), "not a regular file"),
    "/dev/full": (lambda d, suffix: Path("/dev/full"), "/dev/full"),
    "/dev/null": (lambda d, suffix: Path("/dev/null"), "/dev/null"),
    "a link to a file": (lambda d, suffix: _link(d, f"o{suffix}", d / "target.txt"), "symbolic link"),
    "a link to /dev/zero": (lambda d, suffix: _link(d, f"o{suffix}", Path("/dev/zero")), "symbolic link"),
    "a folder": (lambda d, suffix: (d / f"o{suffix}").mkdir() or d / f"o{suffix}", "is a directory"),
}
NOT_A_FOLDER = {key: NOT_A_FILE[key] for key in ("a FIFO", "/dev/full", "/dev/null", "a link to a file")}
#: Commands writing a file (the suffix it must have) and commands writing a folder, at ``out``.
FILE_WRITERS = {"view": (["view", "{run}"], ".html"), "animate": (["animate", "{run}"], ".gif"),
                "export --to mcap": (["export", "{run}", "--to", "mcap"], ".mcap")}  # fmt: skip
FOLDER_WRITERS = {"run": ["run", "{scenario}"], "plot": ["plot", "{run}"], "export --to csv": ["export", "{run}", "--to", "csv"],
                  "sweep": ["sweep", "{sweep}"]}  # fmt: skip
OUTPUT_CASES = {f"{command} --out {kind}": (args, suffix, kind) for command, (args, suffix) in FILE_WRITERS.items() for kind in NOT_A_FILE}
OUTPUT_CASES |= {f"{command} --out {kind}": (args, "", kind) for command, args in FOLDER_WRITERS.items() for kind in NOT_A_FOLDER}


def _snapshot(folder: Path) -> list:
    return sorted((p.name, p.is_symlink(), p.is_dir(), p.is_fifo()) for p in folder.iterdir())


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
@pytest.mark.parametrize("name", OUTPUT_CASES, ids=list(OUTPUT_CASES))
def test_an_output_that_is_no_regular_file_is_refused_without_reading_it(name, saved, tmp_path, runner):
    args, suffix, kind = OUTPUT_CASES[name]
    (tmp_path / "target.txt").write_text("the user's")
    make, words = (NOT_A_FILE if suffix else NOT_A_FOLDER)[kind]
    out = make(tmp_path, suffix)
    before = _snapshot(tmp_path)
    with deadline(60):
        result = runner.invoke(app, [a.format(**saved) for a in args] + ["--out", str(out)])
    assert result.exit_code == 2, result.output[-2000:]
    assert result.output.count("\n") == 1 and result.output.startswith("error: --out "), result.output[-2000:]
    assert words in result.output or "not a directory" in result.output, result.output
    assert _snapshot(tmp_path) == before and (tmp_path / "target.txt").read_text() == "the user's"


USAGE_CASES = {
    "unknown command": (["fly"], "no such command 'fly'; see "),
    "run without --out": (["run", "{scenario}"], "missing option --out; see "),
    "run without a scenario": (["run"], "missing argument SCENARIO; see "),
    "text for --fps": (["animate", "{run}", "--fps", "fast"], "invalid value for --fps"),
    "text for --max-frames": (["view", "{run}", "--max-frames", "many"], "invalid value for --max-frames"),
    "an unknown option": (["run", "{scenario}", "--out", "x", "--colour", "red"], "no such option: --colour"),
    "export without --to": (["export", "{run}"], "missing option --to; see "),
    "an unknown option of the group": (["--verbose"], "no such option: --verbose"),
    "a command name with an escape": (["f\x1b[2Jly"], "no such command 'f\\x1b[2Jly'"),
}


@pytest.mark.parametrize("name", USAGE_CASES, ids=list(USAGE_CASES))
def test_a_usage_error_is_one_line_with_a_hint(name, saved, tmp_path, runner):
    args, words = USAGE_CASES[name]
    result = runner.invoke(app, [a.format(**saved) for a in args])
    assert result.exit_code == 2, result.output
    assert result.output.count("\n") == 1 and result.output.startswith("error: "), result.output
    assert words in result.output and "--help" in result.output and "\x1b" not in result.output, result.output


#: Names that would split a message, forge a line of their own, or reach the terminal as control codes.
CONTROL = {"newline": "a\nerror: forged", "escape": "a\x1b[31mred", "carriage return": "a\rerror: b", "bell": "a\x07"}
NAMED_CASES = {f"{where} with a {kind}": (where, text) for where in ("view --out", "run --out", "animate RUN_DIR")
               for kind, text in CONTROL.items()}  # fmt: skip


@pytest.mark.parametrize("name", NAMED_CASES, ids=list(NAMED_CASES))
def test_a_name_with_control_characters_stays_in_one_line(name, saved, tmp_path, runner):
    where, text = NAMED_CASES[name]
    odd = tmp_path / text
    odd.mkdir()
    (odd / "notes.txt").write_text("the user's")  # a folder that is no output: refused, naming it
    args = {"view --out": ["view", saved["run"], "--out", str(odd)], "run --out": ["run", saved["scenario"], "--out", str(odd)],
            "animate RUN_DIR": ["animate", str(odd), "--out", str(tmp_path / "a.gif")]}[where]  # fmt: skip
    result = runner.invoke(app, args)
    assert result.exit_code == 2, result.output
    assert result.output.count("\n") == 1 and result.output.startswith("error: "), result.output
    assert text.encode("unicode_escape").decode() in result.output and not any(c in result.output[:-1] for c in "\n\r\x1b\x07")


def _refused_in_one_line(result, *words) -> None:
    assert result.exit_code == 2, result.output[-2000:]
    assert result.output.count("\n") == 1 and result.output.startswith("error: "), result.output[-2000:]
    assert "Traceback" not in result.output
    for word in words:
        assert word in result.output, result.output


def _laughs(levels: int) -> str:
    lines = ['a0: &a0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    lines += [f"a{k}: &a{k} [" + ", ".join([f"*a{k - 1}"] * 9) + "]" for k in range(1, levels)]
    return "\n".join(lines) + "\n"


#: crazyflies.yaml files whose message would be huge or split, and what the one line must say.
YAML_CASES = {
    "billion laughs in enabled": (_laughs(7) + "robots:\n  cf1:\n    enabled: *a6\n    initial_position: [0, 0, 0]\n",
                                  "robots.cf1.enabled: must be true or false, got [["),
    "billion laughs in initial_position": (_laughs(7) + "robots:\n  cf1:\n    enabled: true\n    initial_position: *a6\n",
                                           "robots.cf1.initial_position: must be 3 finite numbers"),
    "a robot named with a newline": ('robots:\n  "cf1\\nerror: forged":\n    enabled: true\n    initial_position: [0, 0, 0]\n',
                                     "robots.cf1\\nerror: forged: a robot's name must be"),
    "a robot named with an escape": ('robots:\n  "cf\\e[2J":\n    enabled: true\n    initial_position: [0, 0, 0]\n',
                                     "robots.cf\\x1b[2J: a robot's name must be"),
}


@pytest.mark.parametrize("name", YAML_CASES, ids=list(YAML_CASES))
def test_a_crazyflies_yaml_is_refused_in_one_short_line(name, tmp_path, runner):
    text, words = YAML_CASES[name]
    (tmp_path / "crazyflies.yaml").write_text(text)
    (tmp_path / "s.toml").write_text('agents_from = "crazyflies.yaml"\n[space]\naxes = 2\n[interaction]\nfunction = "improved"\n')
    result = runner.invoke(app, ["run", str(tmp_path / "s.toml"), "--out", str(tmp_path / "out")])
    _refused_in_one_line(result, words)
    assert len(result.output) < 600 and not (tmp_path / "out").exists()


def _npz(path: Path, meta: dict, shape: tuple) -> None:
    """A checkpoint file: ``meta``, and an array whose header declares ``shape`` doubles but holds 64 bytes."""
    meta_npy, header = io.BytesIO(), io.BytesIO()
    np.save(meta_npy, np.array(json.dumps(meta)))
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": shape})
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("meta.npy", meta_npy.getvalue())
        z.writestr("agents.P.npy", header.getvalue() + b"\0" * 64)


CHECKPOINT_CASES = {
    "of another tmem, declaring 2^40 doubles": (lambda s: {"made_by": "tmem 0.0.1"}, (2**40,), "was written by tmem 0.0.1"),
    "of another scenario, declaring 2^40 doubles": (lambda s: {"fingerprint": "0" * 64}, (2**40,), "for another scenario"),
    "of this run, declaring 2^40 doubles": (lambda s: {}, (2**40,), "is not a tmem checkpoint, or is damaged (ValueError)"),
    "of this run, declaring 2^31 x 2^31": (lambda s: {}, (2**31, 2**31), "is not a tmem checkpoint, or is damaged"),
}


@pytest.mark.parametrize("name", CHECKPOINT_CASES, ids=list(CHECKPOINT_CASES))
def test_a_checkpoints_meta_is_checked_before_any_array_is_read(name, saved, tmp_path, runner):
    changes, shape, words = CHECKPOINT_CASES[name]
    scenario = tmem.load(saved["scenario"])
    out = tmp_path / "out"
    meta = {"format": FORMAT, "made_by": made_by(), "fingerprint": fingerprint(scenario, True, None), "step": 10,
            "time": 0.01, "list_builds": 1} | changes(scenario)  # fmt: skip
    _npz(checkpoint_path(out), meta, shape)
    result = runner.invoke(app, ["run", saved["scenario"], "--out", str(out), "--checkpoint-every", "1"])
    _refused_in_one_line(result, words)
    assert not out.exists()


SUMMARY_CASES = {
    "a FIFO": (lambda p: os.mkfifo(p), "summary.json: is not a regular file"),
    "larger than a summary may be": (lambda p: open(p, "wb").truncate(2**28 + 1), "more than a run's summary may be"),
}


@pytest.mark.parametrize("command", ["plot", "view"])
@pytest.mark.parametrize("name", SUMMARY_CASES, ids=list(SUMMARY_CASES))
def test_a_runs_summary_is_read_only_if_it_is_a_regular_file_of_bounded_size(name, command, saved, tmp_path, runner):
    make, words = SUMMARY_CASES[name]
    run = tmp_path / "run"
    shutil.copytree(saved["run"], run)
    (run / "summary.json").unlink()
    make(run / "summary.json")
    with deadline(60):
        result = runner.invoke(app, [command, str(run), "--out", str(tmp_path / ("o.html" if command == "view" else "o"))])
    _refused_in_one_line(result, words)


#: Writers onto a read-only folder, and what the one line names.
READ_ONLY = {
    "view": (["view", "{run}", "--out", "{ro}/v.html"], "--out {ro}/v.html: cannot be written (Read-only file system)"),
    "animate": (["animate", "{run}", "--out", "{ro}/a.gif", "--max-frames", "3"], "--out {ro}/a.gif: cannot be written"),
    "export --to mcap": (["export", "{run}", "--to", "mcap", "--out", "{ro}/x.mcap"], "--out {ro}/x.mcap: cannot be written"),
    "export --to csv": (["export", "{run}", "--to", "csv", "--out", "{ro}/csv"], "--out {ro}/csv: cannot be written"),
    "plot --out": (["plot", "{run}", "--out", "{ro}/p"], "--out {ro}/p: cannot be written"),
    "run": (["run", "{scenario}", "--out", "{ro}/r"], "--out {ro}/r: cannot be written"),
    "run --checkpoint-every": (["run", "{scenario}", "--out", "{ro}/r", "--checkpoint-every", "1"], "cannot be written"),
}


def _can_mount_read_only(folder: Path) -> bool:
    if shutil.which("unshare") is None:
        return False
    probe = subprocess.run(["unshare", "-m", "sh", "-c", f"mount -t tmpfs -o ro tmpfs {folder}"], capture_output=True)
    return probe.returncode == 0


@pytest.mark.parametrize("name", READ_ONLY, ids=list(READ_ONLY))
def test_a_writer_onto_a_read_only_mount_says_one_line(name, saved, tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    if not _can_mount_read_only(ro):
        pytest.skip("no read-only mount here (needs unshare -m and mount)")
    args, words = READ_ONLY[name]
    command = " ".join(f"'{a.format(ro=ro, **saved)}'" for a in args)
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parent.parent / "src")}
    done = subprocess.run(["unshare", "-m", "sh", "-c", f"mount -t tmpfs -o ro tmpfs {ro} && '{sys.executable}' -m tmem {command}"],
                          capture_output=True, text=True, env=env, timeout=300)  # fmt: skip
    assert done.returncode == 2, done.stderr[-2000:]
    assert done.stderr.count("\n") == 1 and done.stderr.startswith("error: "), done.stderr[-2000:]
    assert words.format(ro=ro) in done.stderr
    assert list(ro.iterdir()) == []


@pytest.mark.parametrize("command", ["view", "export --to mcap", "animate"])
def test_a_refused_rename_is_said_in_one_line_whatever_the_clean_up_meets(command, saved, tmp_path, runner, monkeypatch):
    """A read-only file system refuses the rename into place and every removal: the first error is said."""
    def read_only(*args, **kwargs):
        raise OSError(errno.EROFS, "Read-only file system")

    import tmem.files.outputs.replace as replace

    monkeypatch.setattr(replace.os, "replace", read_only)
    monkeypatch.setattr(Path, "unlink", read_only)
    out = tmp_path / {"view": "v.html", "export --to mcap": "x.mcap", "animate": "a.gif"}[command]
    args = {"view": ["view", saved["run"]], "export --to mcap": ["export", saved["run"], "--to", "mcap"],
            "animate": ["animate", saved["run"], "--max-frames", "3"]}[command]  # fmt: skip
    result = runner.invoke(app, [*args, "--out", str(out)])
    _refused_in_one_line(result, f"--out {out}: cannot be written (Read-only file system)")
    assert not out.exists()


def test_the_battery_is_large():
    assert len(OUTPUT_CASES) + len(USAGE_CASES) + len(NAMED_CASES) >= 40
    assert len(YAML_CASES) + len(CHECKPOINT_CASES) + 2 * len(SUMMARY_CASES) + len(READ_ONLY) + 3 >= 20
