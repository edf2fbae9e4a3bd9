"""Words the user reads: the README and docs' snippets run alone and print what they say, every link,
module, file and equation label they name exists, examples say what their numbers are."""

import contextlib
import importlib
import io
import json
import math
import re
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = sorted((ROOT / "docs").glob("*.md"))
PAGES = [README, *DOCS]

FENCE = re.compile(r"^(```|~~~).*?^\1[ \t]*$", re.M | re.S)
LINK = re.compile(r"!?\[((?:[^\[\]]|\[[^\]]*\])*)\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
#: A label of tmem's own equations: a letter and a number in parentheses, (S2), (Q11).
OWN_LABEL = re.compile(r"\(([A-Z][0-9]+)\)")


def prose(text: str) -> str:
    """Markdown without its fenced code blocks (a ``# comment`` there is no heading, a link no link)."""
    return FENCE.sub("", text)


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: link text kept, lower case, punctuation dropped, spaces to hyphens."""
    text = LINK.sub(lambda m: m.group(1), heading)
    return re.sub(r"[^\w\- ]", "", text.strip().lower()).replace(" ", "-")


def headings(path: Path) -> list[tuple[int, str, str]]:
    """Each heading of ``path`` as (level, text, anchor); a repeated anchor gets -1, -2 as GitHub gives it."""
    seen: dict[str, int] = {}
    found = []
    for line in prose(path.read_text()).splitlines():
        m = re.match(r"^(#{1,6})\s+(.*?)\s*#*\s*$", line)
        if m:
            anchor = slug(m.group(2))
            n = seen.get(anchor, 0)
            seen[anchor] = n + 1
            found.append((len(m.group(1)), m.group(2), anchor if n == 0 else f"{anchor}-{n}"))
    return found


def links(path: Path) -> list[str]:
    """The targets of the links and images of ``path``, outside code."""
    text = re.sub(r"`[^`\n]*`", "", prose(path.read_text()))
    return [m.group(2) for m in LINK.finditer(text)]


def section(path: Path, anchor: str) -> str:
    """The text of ``path`` under the heading ``anchor``, up to the next heading of its level or above."""
    lines = path.read_text().splitlines()
    marks = iter(headings(path))
    level, start = None, None
    out = []
    in_fence = False
    for line in lines:
        if re.match(r"^(```|~~~)", line):
            in_fence = not in_fence
        if not in_fence and re.match(r"^#{1,6}\s", line):
            lvl, _, a = next(marks)
            if start is not None and lvl <= level:
                break
            if a == anchor:
                level, start = lvl, True
                continue
        if start:
            out.append(line)
    assert start, f"{path.name}: no heading #{anchor}"
    return "\n".join(out)


def python_blocks(path: Path) -> list[str]:
    return re.findall(r"```python\n(.*?)```", path.read_text(), re.S)


@pytest.fixture(scope="module")
def readme_tour(tmp_path_factory):
    """The README's Python tour run alone in a fresh folder beside the shipped examples: what it printed,
    and the summary it wrote."""
    folder = tmp_path_factory.mktemp("tour")
    (folder / "examples").symlink_to(ROOT / "examples")
    snippet = next(b for b in python_blocks(README) if "tmem.write_run" in b)
    printed = io.StringIO()
    with contextlib.chdir(folder), contextlib.redirect_stdout(printed):
        exec(compile(snippet, "README.md", "exec"), {})  # a fresh namespace: every import must be in it
    return snippet, printed.getvalue(), json.loads((folder / "out/fig9-python/summary.json").read_text())


def test_the_readme_python_tour_prints_what_its_comment_says(readme_tour):
    snippet, printed, _ = readme_tour
    for name in ("load", "simulate", "summarize", "write_run"):
        assert f"tmem.{name}(" in snippet
    said = re.search(r"print\(.*\)\s*#\s*(.+)$", snippet, re.M).group(1).strip()
    assert printed.strip() == said


def test_the_readme_run_prints_the_table_it_shows(readme_tour):
    """The tour's `tmem run` of the unedited examples/fig9.toml: the table shown is the one the run prints."""
    from rich.console import Console

    from tmem.cli.terminal import summary_table

    _, _, summary = readme_tour
    shown = re.search(r"Unedited, the run prints its summary:\n\n```\n(.*?)```", README.read_text(), re.S).group(1)
    table, written = shown.rstrip("\n").rsplit("\n", 1)
    console = Console(width=100, file=io.StringIO(), color_system=None, legacy_windows=False)
    console.print(summary_table({"fig9": summary}))
    assert console.file.getvalue().rstrip("\n") == table
    assert written == "written to out/my/"


@pytest.mark.parametrize("block", range(len(python_blocks(ROOT / "docs/python.md"))))
def test_the_python_pages_snippets_run_alone(block, tmp_path, monkeypatch):
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    monkeypatch.chdir(tmp_path)
    snippet = python_blocks(ROOT / "docs/python.md")[block]
    exec(compile(snippet, "docs/python.md", "exec"), {})  # a fresh namespace: every import must be in it


def test_the_batch_snippet_is_on_the_python_page():
    assert any("run_batch" in b for b in python_blocks(ROOT / "docs/python.md"))


def test_the_readme_is_a_front_page():
    """At most about 200 lines; its Quick start has exactly the two commands, and CI runs the second."""
    text = README.read_text()
    assert len(text.splitlines()) <= 200
    quick = re.search(r"^## Quick start\n(.*?)^## ", text, re.S | re.M).group(1)
    commands = re.findall(r"```sh\n(.*?)```", quick, re.S)
    assert len(commands) == 1
    setup, tests = commands[0].splitlines()
    assert setup == "python3 -m venv .venv && .venv/bin/pip install -e . && .venv/bin/tmem paper --out out/paper"
    assert tests == "python3 -m venv .venv && .venv/bin/pip install -e '.[test]' && .venv/bin/pytest"
    ci = [line.replace(" install -q ", " install ") for line in (ROOT / ".ci/run").read_text().splitlines()]
    assert tests in ci  # CI runs it, pip made quiet
    assert re.search(r"!\[[^\]]+\]\(docs/images/[\w-]+\.png\)", text)


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_relative_link_resolves(page):
    """README.md and docs/*.md: every link to a file names one that exists, every anchor a heading of it."""
    broken = []
    for target in links(page):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto:
            continue
        file, _, anchor = target.partition("#")
        path = (page.parent / file).resolve() if file else page
        if not path.exists():
            broken.append(f"{target}: no such file")
        elif anchor and path.suffix == ".md" and anchor not in {a for _, _, a in headings(path)}:
            broken.append(f"{target}: no such heading")
    assert not broken, broken


def test_the_link_checker_sees_a_broken_link(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("# A title\n\n## The gas's counts\n\n[ok](#the-gass-counts) [bad](#the-gas-s-counts)\n```sh\n# not a heading\n```\n")
    assert [a for _, _, a in headings(page)] == ["a-title", "the-gass-counts"]
    assert links(page) == ["#the-gass-counts", "#the-gas-s-counts"]


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_module_path_named_imports(page):
    """``tmem.a.b`` in the text is a module that imports, or a name in one; none of the old top-level paths."""
    import warnings

    missing = []
    for path in sorted(set(re.findall(r"\btmem(?:\.[A-Za-z_]\w*)+", page.read_text()))):
        parts = path.split(".")
        for i in range(len(parts), 0, -1):
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("error", DeprecationWarning)  # a moved module's stand-in
                    obj = importlib.import_module(".".join(parts[:i]))
            except ModuleNotFoundError:
                continue
            except DeprecationWarning:
                missing.append(f"{path}: an old path")
                break
            for name in parts[i:]:
                obj = getattr(obj, name, None)
            if obj is None:
                missing.append(path)
            break
    assert not missing, missing


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_file_named_exists(page):
    """The examples, scripts, benchmarks and tests the text names are shipped."""
    named = re.findall(r"\b((?:examples|benchmarks|docs/scripts|tests)/[\w./*-]*\w)", page.read_text())
    missing = [n for n in named if not (list(ROOT.glob(n)) if "*" in n else (ROOT / n).exists())]
    assert not missing, missing


def test_the_index_lists_every_page_once_and_the_readme_links_it():
    index = ROOT / "docs/index.md"
    listed = {t for t in links(index) if re.fullmatch(r"\w+\.md", t)}
    assert sorted(listed) == sorted(p.name for p in DOCS if p != index)
    numbered = re.findall(r"^\s*\d+\. \[([\w.]+\.md)\]", index.read_text(), re.M)
    assert sorted(numbered) == sorted(set(numbered)) == sorted(p.name for p in DOCS if p != index)
    assert "docs/index.md" in links(README)


def equation_rows() -> dict[str, tuple[str, str]]:
    """The index's table of equation labels: label -> (what it is, link)."""
    text = section(ROOT / "docs/index.md", "equation-labels")
    rows = {}
    for line in text.splitlines():
        m = re.match(r"^\| \((\w+)\) \| (.+) \| \[[^\]]+\]\(([^)]+)\) \|$", line)
        if m:
            assert m.group(1) not in rows, f"({m.group(1)}) twice"
            rows[m.group(1)] = (m.group(2), m.group(3))
    return rows


def test_the_equation_table_has_every_label_of_the_docs_and_the_code():
    """Every (S2), (Q11) ... of docs/*.md and src/ has a row, and every row a label that is used; the paper's (1)-(11) too."""
    used = set()
    for path in [README, *DOCS, *(ROOT / "src").rglob("*.py")]:
        if path.name != "index.md":
            used |= set(OWN_LABEL.findall(path.read_text()))
    rows = equation_rows()
    own = {label for label in rows if not label.isdigit()}
    assert own == used
    assert {label for label in rows if label.isdigit()} == {str(n) for n in range(1, 12)}
    assert {"S1", "C1", "T1", "W1", "G1", "Q11", "D6"} <= own  # the scan found the labels at all


def test_each_tmem_label_is_derived_in_the_section_its_row_names():
    for label, (_, target) in equation_rows().items():
        file, _, anchor = target.partition("#")
        text = section(ROOT / "docs" / file, anchor)
        if not label.isdigit():
            assert f"({label})" in text, f"({label}) is not in {target}"


def test_gas2d_box_is_the_one_its_comment_computes():
    """One neighbour within R + R_j on average (docs/swarms.md): sqrt(N pi (R + R_j)^2 / 1)."""
    data = tomllib.loads((ROOT / "examples/swarm/gas2d.toml").read_text())
    side = math.sqrt(data["swarm"]["n"] * math.pi * 40.0**2 / 1)
    assert all(abs(b - side) < 1.0 for b in data["space"]["box"]), (data["space"]["box"], side)


def test_user_docs_do_not_speak_of_issues_or_announce_what_exists():
    assert "the issue" not in (ROOT / "docs/swarms.md").read_text()
    reproduction = (ROOT / "docs/reproduction.md").read_text()
    assert "will give the distributions" not in reproduction and "encounters.md" in reproduction
