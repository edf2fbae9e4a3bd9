"""Words the user reads: the README's snippets run alone, examples say what their numbers are."""

import math
import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_readme_batch_snippet_runs_alone():
    text = (ROOT / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    snippet = next(b for b in blocks if "run_batch" in b)
    exec(compile(snippet, "README.md", "exec"), {})  # a fresh namespace: every import must be in it


def test_gas2d_box_is_the_one_its_comment_computes():
    """One neighbour within R + R_j on average (docs/swarms.md): sqrt(N pi (R + R_j)^2 / 1)."""
    data = tomllib.loads((ROOT / "examples/swarm/gas2d.toml").read_text())
    side = math.sqrt(data["swarm"]["n"] * math.pi * 40.0**2 / 1)
    assert all(abs(b - side) < 1.0 for b in data["space"]["box"]), (data["space"]["box"], side)


def test_user_docs_do_not_speak_of_issues_or_announce_what_exists():
    assert "the issue" not in (ROOT / "docs/swarms.md").read_text()
    reproduction = (ROOT / "docs/reproduction.md").read_text()
    assert "will give the distributions" not in reproduction and "encounters.md" in reproduction
