"""`tmem plot`: a saved run's figures drawn again, into the run or into --out, whole or not at all."""

import json
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

import tmem.figures.plot
from tmem.cli.main import app
from tmem.files.outputs import MANIFEST

FIGURES = ["distance.png", "paths.png", "shape.png", "velocity.png"]  # two agents in the plane, no formation


@pytest.fixture(scope="module")
def saved_run(pair_2d_factory):
    """A run written by `tmem run`: two agents in the plane, short and coarse."""
    scenario = pair_2d_factory(20.0, 100)
    out = scenario.parent / "run"
    result = CliRunner().invoke(app, ["run", str(scenario), "--out", str(out)])
    assert result.exit_code == 0, result.output
    return out


@pytest.fixture
def run_dir(saved_run, tmp_path):
    copy = tmp_path / "run"
    shutil.copytree(saved_run, copy)
    return copy


def invoke(*args):
    result = CliRunner().invoke(app, ["plot", *map(str, args)])
    return result.exit_code, result.stderr, result.stdout


def snapshot(directory: Path) -> dict:
    return {str(p.relative_to(directory)): p.read_bytes() for p in sorted(directory.rglob("*")) if p.is_file()}


def refused(code, stderr, *words):
    assert code == 2, stderr
    assert stderr.count("\n") == 1 and stderr.startswith("error: ") and "Traceback" not in stderr, stderr
    for word in words:
        assert word in stderr, stderr


def test_redrawn_in_place_the_figures_are_those_tmem_run_drew(run_dir):
    """The same function draws them from the same numbers: the same PNG bytes."""
    drawn = {name: (run_dir / name).read_bytes() for name in FIGURES}
    (run_dir / "velocity.png").unlink()
    (run_dir / "animation.gif").write_bytes(b"GIF89a the user's")
    code, stderr, stdout = invoke(run_dir)
    assert code == 0, stderr
    assert stdout.startswith("written velocity.png, distance.png, ") and stdout.rstrip().endswith(f"to {run_dir}/")
    for name in FIGURES:
        assert (run_dir / name).read_bytes() == drawn[name], name
    assert (run_dir / "animation.gif").read_bytes() == b"GIF89a the user's"
    assert sorted(p.name for p in run_dir.iterdir()) == sorted([MANIFEST, "animation.gif", "summary.json", "trajectory.nc", *FIGURES])


def test_figures_new_to_a_run_are_added_to_its_manifest(run_dir, pair_2d_factory):
    """A run written before a figure existed gets it listed: `tmem run` may replace the directory later."""
    manifest = json.loads((run_dir / MANIFEST).read_text())
    manifest["files"].remove("shape.png")
    (run_dir / MANIFEST).write_text(json.dumps(manifest))
    (run_dir / "shape.png").unlink()
    assert invoke(run_dir)[0] == 0
    assert json.loads((run_dir / MANIFEST).read_text())["files"] == sorted(["summary.json", "trajectory.nc", *FIGURES])
    result = CliRunner().invoke(app, ["run", str(pair_2d_factory(5.0, 100)), "--out", str(run_dir)])
    assert result.exit_code == 0, result.output


def test_a_run_of_a_paper_output_is_listed_in_the_papers_manifest(run_dir, tmp_path):
    paper = tmp_path / "paper"
    paper.mkdir()
    shutil.copytree(run_dir, paper / "fig9")
    (paper / "fig9" / MANIFEST).unlink()
    (paper / "fig9" / "shape.png").unlink()
    listed = [f"fig9/{name}" for name in ("distance.png", "paths.png", "summary.json", "trajectory.nc", "velocity.png")]
    (paper / MANIFEST).write_text(json.dumps({"command": "paper", "tmem": "0.1.0", "files": [*listed, "report.md"]}))
    (paper / "report.md").write_text("# report")
    assert invoke(paper / "fig9")[0] == 0
    assert (paper / "fig9" / "shape.png").is_file()
    assert "fig9/shape.png" in json.loads((paper / MANIFEST).read_text())["files"]
    code, stderr, _ = invoke(paper)
    refused(code, stderr, f"no trajectory.nc or summary.json in {paper}", f"(such as {paper / 'fig9'})")


def test_into_out_only_the_figures_and_again_replaced_whole(run_dir, tmp_path):
    out = tmp_path / "figures"
    before = snapshot(run_dir)
    for _ in range(2):
        code, stderr, _ = invoke(run_dir, "--out", out)
        assert code == 0, stderr
    assert sorted(p.name for p in out.iterdir()) == sorted([MANIFEST, *FIGURES])
    assert json.loads((out / MANIFEST).read_text())["command"] == "plot"
    assert snapshot(run_dir) == before
    for name in FIGURES:
        assert (out / name).read_bytes() == before[name]


@pytest.mark.parametrize(
    "make, words",
    [
        (lambda d: d / "nowhere", ["plot: ", "nowhere: no such folder"]),
        (lambda d: (d / "empty").mkdir() or d / "empty", ["no trajectory.nc or summary.json in"]),
        (lambda d: (d / "afile").write_text("x") and d / "afile", ["afile: is a file, not a run folder"]),
    ],
    ids=["missing", "empty folder", "a file"],
)
def test_what_is_not_a_run_is_refused_in_one_line(tmp_path, make, words):
    target = make(tmp_path)
    before = sorted(p.name for p in tmp_path.iterdir())
    refused(*invoke(target, "--out", tmp_path / "out")[:2], *words)
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_a_damaged_trajectory_is_refused_naming_it(run_dir):
    path = run_dir / "trajectory.nc"
    path.write_bytes(path.read_bytes()[:5000])
    before = snapshot(run_dir)
    refused(*invoke(run_dir)[:2], f"plot: {path}: cannot be read as a run's trajectory (")
    assert snapshot(run_dir) == before


def test_a_users_file_under_a_figures_name_is_never_replaced(run_dir):
    (run_dir / "shape.png").write_bytes(b"my own sketch")
    manifest = json.loads((run_dir / MANIFEST).read_text())
    manifest["files"].remove("shape.png")
    (run_dir / MANIFEST).write_text(json.dumps(manifest))
    (run_dir / "velocity.png").unlink()
    before = snapshot(run_dir)
    refused(*invoke(run_dir)[:2], f"{run_dir / 'shape.png'}: exists and was not written by tmem")
    assert snapshot(run_dir) == before
    assert not [p for p in run_dir.iterdir() if p.name.startswith(".figures.")]


def test_out_holding_something_else_is_refused(run_dir, tmp_path):
    out = tmp_path / "notes"
    out.mkdir()
    (out / "mine.txt").write_text("precious")
    refused(*invoke(run_dir, "--out", out)[:2], "holds files that are not marked as a tmem output (mine.txt)")
    assert snapshot(out) == {"mine.txt": b"precious"}


@pytest.mark.parametrize("into_out", [False, True], ids=["in place", "--out"])
def test_interrupted_while_drawing_leaves_everything_as_it_was(run_dir, tmp_path, monkeypatch, into_out):
    """Ctrl-C after some figures are drawn: none of them replaces anything, no temporary folder stays."""
    draw = tmem.figures.plot.write_figures

    def interrupted(trajectory, directory):
        draw(trajectory, directory)
        raise KeyboardInterrupt

    monkeypatch.setattr(tmem.figures.plot, "write_figures", interrupted)
    (run_dir / "velocity.png").write_bytes(b"old")
    before = snapshot(run_dir)
    out = tmp_path / "figures" if into_out else None
    with pytest.raises(KeyboardInterrupt):
        tmem.figures.plot.redraw(run_dir, out)
    assert snapshot(run_dir) == before
    assert not (tmp_path / "figures").exists()
    assert [p.name for p in tmp_path.iterdir()] == ["run"]
