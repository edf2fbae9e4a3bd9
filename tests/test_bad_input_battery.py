"""A battery of bad inputs, generated field by field: each is refused in one line naming the field.

Every case is given to the command line (``tmem run``, ``tmem sweep`` or ``tmem animate``) and
must end with exit status 2, exactly one line of output naming the field (or argument) at fault,
no traceback, and nothing written under ``--out``.  The cases are generated systematically:

* every numeric field of a scenario x {negative, zero, nan, inf, -inf, huge, wrong type, list, table};
* every table x {not a table, an unknown key}; every choice of names x {a typo};
* inputs once accepted although wrong, or refused with a traceback, and their neighbours: a periodic box narrower than
  R + R_j, duplicate or empty ``record_agents``, ``pairs = []``, a couple command with a function
  that never couples, a ``dt`` too coarse for the closed loop, ``im_r`` so small that K_P
  underflows, negative seeds, a huge ``record_every``, deeply nested TOML, a FIFO or a device as
  the file, swarms and formations too big for memory, long or unprintable names;
* sweep files (``[random]`` choices of mixed kinds, bad ranges, bad keys) and ``animate`` arguments.

``tests/test_bad_input.py`` keeps its own cases; those are left out here.  The battery goes on in
``tests/test_bad_output_battery.py``: outputs that are not regular files, usage errors, names with
control characters.
"""

from __future__ import annotations

import json
import math
import os
import tomllib
from pathlib import Path

import pytest
from typer.testing import CliRunner

import tmem
from tmem.cli.main import app

FIG9 = tomllib.loads(tmem.preset("fig9").to_toml())
SWARM = {
    "space": {"axes": 2, "periodic": True, "box": [200.0, 200.0]},
    "interaction": {"function": "repulsion"},
    "swarm": {"n": 10, "seed": 1, "speed_rms": 1.0},
    "simulation": {"dt": 0.01, "duration": 1.0, "record_every": 10},
}
REPEL = {"function": "repulsion"}
FORMATION = {
    "space": {"axes": 2},
    "interaction": {"function": "improved"},
    "formation": {"kind": "hex", "n": 7, "seed": 1},
    "simulation": {"dt": 0.01, "duration": 1.0, "record_every": 10},
}


class Raw(str):
    """TOML text written as it is (for values TOML cannot spell through json)."""


def _value(v) -> str:
    if isinstance(v, Raw):
        return str(v)
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return ("-inf" if v < 0 else "inf") if math.isinf(v) else ("nan" if math.isnan(v) else repr(v))
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(v)


def dump(data: dict) -> str:
    """``data`` as TOML: scalars first, then tables, then arrays of tables."""
    lines = [f"{json.dumps(k)} = {_value(v)}" for k, v in data.items()
             if not isinstance(v, dict) and not (isinstance(v, list) and v and all(isinstance(x, dict) for x in v))]  # fmt: skip
    for k, v in data.items():
        if isinstance(v, dict):
            lines += [f"[{k}]"] + [f"{json.dumps(kk)} = {_value(vv)}" for kk, vv in v.items()]
    for k, v in data.items():
        if isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for item in v:
                lines += [f"[[{k}]]"] + [f"{json.dumps(kk)} = {_value(vv)}" for kk, vv in item.items()]
    return "\n".join(lines) + "\n"


def changed(base: dict, path: str, value) -> dict:
    """A deep copy of ``base`` with ``path`` (``table.key``, ``agents.0.velocity``) set."""
    data = json.loads(json.dumps(base))
    parts = [int(p) if p.isdigit() else p for p in path.split(".")]
    node = data
    for part in parts[:-1]:
        node = node.setdefault(part, {}) if isinstance(node, dict) else node[part]
    node[parts[-1]] = value
    return data


CASES: dict[str, tuple[str, str]] = {}  # id -> (scenario text, the field the line must name)


def case(name: str, text: str | dict, field: str) -> None:
    assert name not in CASES, name
    CASES[name] = (text if isinstance(text, str) else dump(text), field)


# -- every numeric field x every kind of bad value ---------------------------------------------------

POSITIVE = ["model.kp", "model.kd", "model.g", "controller.r_l", "controller.im_r", "interaction.radius",
            "interaction.c_max", "interaction.d_t", "interaction.eps", "simulation.dt", "simulation.duration"]  # fmt: skip
NON_NEGATIVE = ["controller.im_l", "commands.0.time"]
SIGNED = ["agents.0.position", "agents.0.velocity", "agents.0.tilt", "agents.0.tilt_rate"]
INTEGER = ["simulation.record_every"]
BAD = {
    "negative": -1.0,
    "zero": 0.0,
    "nan": math.nan,
    "inf": math.inf,
    "-inf": -math.inf,
    "huge": 1e300,
    "string": "3",
    "bool": True,
    "list": [1.0, 2.0],
    "table": {"value": 1.0},
}
#: Kept in tests/test_bad_input.py.
ALREADY = {("model.kp", "nan"), ("model.kp", "huge"), ("model.kp", "string"), ("model.kp", "bool"),
           ("interaction.radius", "zero"), ("interaction.radius", "negative"), ("simulation.dt", "zero"),
           ("simulation.duration", "negative"), ("interaction.c_max", "zero"), ("interaction.eps", "negative"),
           ("agents.0.position", "inf"), ("controller.r_l", "negative"), ("controller.r_l", "zero")}  # fmt: skip


def _field_name(path: str) -> str:
    table, *rest = path.split(".")
    return f"{table}[{rest[0]}].{rest[1]}" if rest and rest[0].isdigit() else path


for path in POSITIVE + NON_NEGATIVE + SIGNED + INTEGER:
    for kind, value in BAD.items():
        if (path, kind) in ALREADY:
            continue
        if kind in ("negative", "zero") and path in SIGNED:
            continue  # valid there
        if kind == "zero" and path in NON_NEGATIVE:
            continue
        if kind == "list" and path in SIGNED:
            value = [1.0, 2.0, 3.0]  # one axis: a list of three is the wrong size
        case(f"{path} {kind}", changed(FIG9, path, value), _field_name(path))
for kind, value in {"fraction": 10.5, "2**63": 2**63, "beyond the steps": 600_001}.items():
    case(f"simulation.record_every {kind}", changed(FIG9, "simulation.record_every", value), "simulation.record_every")
for path in ("swarm.n", "swarm.seed", "swarm.speed_rms", "neighbors.skin"):
    for kind in ("negative", "nan", "string"):
        case(f"{path} {kind}", changed(SWARM, path, BAD[kind]), path)
for path in ("formation.n", "formation.seed", "formation.jitter", "formation.d_t"):
    for kind in ("negative", "nan", "string"):
        case(f"{path} {kind}", changed(FORMATION, path, BAD[kind]), path)

MISSION = {**FORMATION, "navigation": {"legs": [{"time": 0.0, "action": "goto", "target": [100.0, 0.0], "speed": 2.0}]},
           "safety": {"radius": 3.0}}  # fmt: skip
for path, field in [("navigation.bandwidth", "navigation.bandwidth"), ("navigation.share", "navigation.share"),
                    ("navigation.legs.0.time", "navigation.legs[0].time"), ("navigation.legs.0.speed", "navigation.legs[0].speed"),
                    ("safety.radius", "safety.radius"), ("safety.range", "safety.range")]:  # fmt: skip
    for kind in ("negative", "nan", "string", "huge"):
        if kind == "huge" and path in ("navigation.legs.0.speed", "safety.range"):
            continue  # a huge speed or range is a choice, not an error
        case(f"{path} {kind}", changed(MISSION, path, BAD[kind]), field)
case("navigation.legs.0.target wrong size", changed(MISSION, "navigation.legs.0.target", [1.0]), "navigation.legs[0].target")
case("navigation.legs.0.action typo", changed(MISSION, "navigation.legs.0.action", "goto!"), "navigation.legs[0].action")
case("formation.min_spacing without scatter", changed(MISSION, "formation.min_spacing", 30.0), "min_spacing")
case("swarm.min_spacing too wide", changed(SWARM, "swarm.min_spacing", 150.0), "swarm.min_spacing")
RESHAPE = changed(MISSION, "navigation.legs", [{"time": 0.0, "action": "hold"},
                                               {"time": 1.0, "action": "reshape", "shape": "chain", "speed": 2.0}])  # fmt: skip
case("navigation.legs.1.shape unknown", changed(RESHAPE, "navigation.legs.1.shape", "star"), "navigation.legs[1].shape")
case("navigation.legs.1.shape missing", changed(RESHAPE, "navigation.legs.1", {"time": 1.0, "action": "reshape", "speed": 2.0}),
     "navigation.legs[1].shape")
case("navigation.legs.1.shape too small", changed(RESHAPE, "navigation.legs.1.shape", "triangle"), "navigation.legs[1].shape")
case("navigation.legs.1.speed list", changed(RESHAPE, "navigation.legs.1.speed", [1.0, 2.0]), "navigation.legs[1].speed")
case("navigation.legs.1.speed negative", changed(RESHAPE, "navigation.legs.1.speed", -1.0), "navigation.legs[1].speed")
case("navigation.legs.0.shape unused", changed(RESHAPE, "navigation.legs.0.shape", "ring"), "navigation.legs[0].shape")

# -- every table x {not a table, an unknown key} -------------------------------------------------------

for table, base in [("model", FIG9), ("controller", FIG9), ("interaction", FIG9), ("simulation", FIG9),
                    ("space", FIG9), ("neighbors", FIG9), ("swarm", SWARM), ("formation", FORMATION),
                    ("navigation", MISSION), ("safety", MISSION)]:  # fmt: skip
    case(f"{table} not a table", changed(base, table, 3), table)
    case(f"{table} unknown key", changed(base, f"{table}.colour", 1.0), f"{table}.colour")
for table in ("agents", "commands"):
    case(f"{table} not a list", changed(FIG9, table, 3), table)
    case(f"{table} unknown key", changed(FIG9, f"{table}.0.colour", 1.0), f"{table}[0].colour")
case("name not text", changed(FIG9, "name", 3), "name")

# -- every choice of names x a typo ------------------------------------------------------------------

for path, base, typo in [("model.kind", FIG9, "lineer"), ("interaction.function", FIG9, "improvd"),
                         ("interaction.switch_at", FIG9, "windows"), ("neighbors.method", FIG9, "verlett"),
                         ("formation.kind", FORMATION, "hexagon"), ("commands.0.action", FIG9, "uncuple")]:  # fmt: skip
    case(f"{path} typo", changed(base, path, typo), _field_name(path))
case("space.axes 4", changed(FIG9, "space.axes", 4), "space.axes")
case("space.periodic as text", changed(SWARM, "space.periodic", "yes"), "space.periodic")

# -- accepted although wrong ----------------------------------------------------------------------------

for side in (10.0, 39.9):
    case(f"periodic box {side} below reach", changed(SWARM, "space.box", [side, 200.0]), "space.box[0]")
case("periodic box second side below reach", changed(SWARM, "space.box", [200.0, 20.0]), "space.box[1]")
case("periodic box below a wider reach", changed(changed(SWARM, "interaction.radius", 60.0), "space.box", [100.0, 100.0]),
     "space.box[0]")
# Empty is allowed where there are pairs to record (tests/test_swarm.py); refused where nothing would be.
case("record_agents empty", changed(changed(SWARM, "swarm.n", 40), "simulation.record_agents", []), "simulation.record_agents")
case("record_agents empty, 3-D", {"space": {"axes": 3, "box": [500.0, 500.0, 500.0]}, "swarm": {"n": 33}, "interaction": REPEL,
                                  "simulation": {"record_agents": []}}, "simulation.record_agents")  # fmt: skip
case("record_agents repeated", changed(FIG9, "simulation.record_agents", [0, 0]), "simulation.record_agents[1]")
case("record_agents repeated later", changed(SWARM, "simulation.record_agents", [1, 2, 3, 2]), "simulation.record_agents[3]")
case("pairs empty", changed(FIG9, "commands.0", {"time": 29.0, "action": "uncouple", "pairs": []}), "commands[0].pairs")
case("pairs repeated", changed(FIG9, "commands.0", {"time": 29.0, "action": "uncouple", "pairs": [[0, 1], [1, 0]]}),
     "commands[0].pairs[1]")
case("pairs empty on a formation", changed(FORMATION, "commands", [{"time": 0.5, "action": "uncouple", "pairs": []}]),
     "commands[0].pairs")
for function in ("repulsion", "attraction"):
    couple = changed(changed(FIG9, "interaction.function", function), "commands.0.action", "couple")
    case(f"couple command with {function}", couple, "commands[0].action")
case("couple every pair with repulsion", changed(changed(FIG9, "interaction.function", "repulsion"), "commands.0",
                                                  {"time": 1.0, "action": "couple"}), "commands[0].action")  # fmt: skip
for dt in (0.02, 0.05, 0.1, 0.5):
    case(f"dt {dt} too coarse", changed(FIG9, "simulation.dt", dt), "simulation.dt")
case("dt too coarse for fast roots", changed(changed(FIG9, "controller.r_l", 300.0), "simulation.dt", 0.001), "simulation.dt")
case("dt too coarse for a fast right pair", changed(changed(FIG9, "controller.im_r", 200.0), "simulation.dt", 0.001),
     "simulation.dt")

# -- validation that let tracebacks through --------------------------------------------------------------

for im_r in (1e-160, 1e-200, 5e-324):
    case(f"im_r {im_r} underflows K_P", changed(FIG9, "controller.im_r", im_r), "controller.im_r")
case("r_l and im_l underflow K_P", changed(changed(FIG9, "controller.r_l", 1e-200), "controller.im_l", 0.0), "controller.r_l")
for seed in (-1, -(2**63)):
    case(f"swarm seed {seed}", changed(SWARM, "swarm.seed", seed), "swarm.seed")
    case(f"formation seed {seed}", changed(FORMATION, "formation.seed", seed), "formation.seed")
case("deep arrays", dump(FIG9) + "x = " + "[" * 3000 + "]" * 3000 + "\n", "nested too deeply")
case("deep inline tables", "x = " + "{a = " * 3000 + "1" + "}" * 3000 + "\n" + dump(FIG9), "nested too deeply")
# 10^7 agents may fit a large machine once recorded less: the line then names what to cut.
for n in (10**7, 10**8, 10**9, 10**10):
    field = "agents would need" if n == 10**7 else None
    big = changed(SWARM, "swarm", {"n": n, "region": [1e6, 1e6]}) | {"space": {"axes": 2}}
    case(f"swarm of {n:.0e}", big, field or "swarm.n")
    few_records = {"record_agents": [0], "record_every": 600000} if field is None else {}  # then 10^7 fits
    case(f"3-D swarm of {n:.0e}", {"space": {"axes": 3, "box": [1e6, 1e6, 1e6]}, "swarm": {"n": n}, "interaction": REPEL,
                                   "simulation": few_records}, field or "swarm.n")  # fmt: skip
    for kind in ("chain", "ring", "hex"):
        case(f"{kind} of {n:.0e}", changed(FORMATION, "formation", {"kind": kind, "n": n}), field or "formation.n")
case("records of a big swarm", changed(SWARM, "swarm.n", 10**6) | {"simulation": {"record_every": 1}}, "simulation.record_every")
for length in (201, 10**4, 10**6):
    case(f"name of {length} characters", changed(FIG9, "name", "x" * length), "name")
for char in ("\x00", "\x1b", "\x07", "\x7f", "\u200b", "\n"):
    case(f"name with {char!r}", changed(FIG9, "name", f"run{char}1"), "name")


@pytest.mark.parametrize("base", [FIG9, SWARM, FORMATION, MISSION], ids=["fig9", "swarm", "formation", "mission"])
def test_the_bases_are_valid(base):
    tmem.scenario.loads(dump(base))


@pytest.fixture
def runner():
    return CliRunner()


def _assert_refused(result, field: str, out: Path, inputs: set[str], folder: Path) -> None:
    assert result.exit_code == 2, (result.exit_code, result.output[-2000:])
    lines = result.output.strip().splitlines()
    assert len(lines) == 1, result.output[-2000:]
    assert field in lines[0], lines[0][:2000]
    assert "Traceback" not in result.output
    assert not out.exists()
    assert {p.name for p in folder.iterdir()} <= inputs


@pytest.fixture(autouse=True)
def no_simulation(monkeypatch):
    """A case that validation lets through must fail here, not run (a 10^7-agent run would take minutes)."""
    import tmem.engine

    def refuse(*args, **kwargs):
        raise AssertionError("validation let the case through to the simulation")

    monkeypatch.setattr(tmem.engine, "simulate", refuse)


@pytest.mark.parametrize("name", CASES, ids=list(CASES))
def test_bad_scenario(name, tmp_path, runner):
    text, field = CASES[name]
    (tmp_path / "bad.toml").write_text(text)
    out = tmp_path / "out"
    result = runner.invoke(app, ["run", str(tmp_path / "bad.toml"), "--out", str(out)])
    _assert_refused(result, field, out, {"bad.toml"}, tmp_path)


# -- files that are not scenario files -------------------------------------------------------------------


def _fifo(path: Path) -> None:
    os.mkfifo(path)


def _huge(path: Path) -> None:
    with open(path, "wb") as f:
        f.truncate(17 * 2**20)  # sparse: 17 MiB of NULs


def _link_to_zero(path: Path) -> None:
    path.symlink_to("/dev/zero")


SPECIAL = {"fifo": (_fifo, "not a regular file"), "larger than 16 MiB": (_huge, "bytes, more than"),
           "link to /dev/zero": (_link_to_zero, "not a regular file")}  # fmt: skip


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
@pytest.mark.parametrize("command", ["run", "sweep"])
@pytest.mark.parametrize("kind", SPECIAL, ids=list(SPECIAL))
def test_special_file(kind, command, tmp_path, runner):
    make, reason = SPECIAL[kind]
    make(tmp_path / "bad.toml")
    out = tmp_path / "out"
    result = runner.invoke(app, [command, str(tmp_path / "bad.toml"), "--out", str(out)])
    _assert_refused(result, reason, out, {"bad.toml"}, tmp_path)


@pytest.mark.parametrize("command", ["run", "sweep"])
def test_dev_zero(command, tmp_path, runner):
    out = tmp_path / "out"
    result = runner.invoke(app, [command, "/dev/zero", "--out", str(out)])
    _assert_refused(result, "/dev/zero: is not a regular file", out, set(), tmp_path)


# -- sweep files ----------------------------------------------------------------------------------------

SWEEP = 'name = "s"\nbase = "fig9"\n'
SWEEP_CASES = {
    "choice of numbers and text": (SWEEP + 'cases = 2\n[random]\n"interaction.c_max" = { choice = [0.1, "big", 0.2] }\n',
                                   "random.interaction.c_max.choice"),
    "choice of text and numbers": (SWEEP + 'cases = 2\n[random]\n"interaction.switch_at" = { choice = ["window", 1] }\n',
                                   "random.interaction.switch_at.choice"),
    "choice of booleans and numbers": (SWEEP + 'cases = 2\n[random]\n"interaction.c_max" = { choice = [true, 0.1] }\n',
                                       "random.interaction.c_max.choice"),
    "choice of lists and numbers": (SWEEP + 'cases = 2\n[random]\n"agents.0.velocity" = { choice = [[1.0], -1.0] }\n',
                                    "random.agents.0.velocity.choice"),
    "grid of numbers and text": (SWEEP + '[grid]\n"interaction.c_max" = [0.1, "big"]\n', "grid.interaction.c_max"),
    "choice empty": (SWEEP + 'cases = 2\n[random]\n"interaction.c_max" = { choice = [] }\n', "random.interaction.c_max.choice"),
    "two kinds at once": (SWEEP + 'cases = 2\n[random]\n"interaction.c_max" = { uniform = [0.1, 0.2], normal = [0.1, 0.01] }\n',
                          "random.interaction.c_max"),
    "uniform reversed": (SWEEP + 'cases = 2\n[random]\n"interaction.c_max" = { uniform = [0.2, 0.1] }\n',
                         "random.interaction.c_max.uniform"),
    "uniform nan": (SWEEP + 'cases = 2\n[random]\n"interaction.c_max" = { uniform = [nan, 0.1] }\n',
                    "random.interaction.c_max.uniform"),
    "loguniform from zero": (SWEEP + 'cases = 2\n[random]\n"interaction.c_max" = { loguniform = [0.0, 0.1] }\n',
                             "random.interaction.c_max.loguniform"),
    "normal with negative spread": (SWEEP + 'cases = 2\n[random]\n"interaction.c_max" = { normal = [0.1, -0.1] }\n',
                                    "random.interaction.c_max.normal"),
    "unknown distribution": (SWEEP + 'cases = 2\n[random]\n"interaction.c_max" = { gauss = [0.1, 0.1] }\n',
                             "random.interaction.c_max.gauss"),
    "random without cases": (SWEEP + '[random]\n"interaction.c_max" = { uniform = [0.1, 0.2] }\n', "cases"),
    "cases without random": (SWEEP + "cases = 3\n", "cases"),
    "cases zero": (SWEEP + 'cases = 0\n[random]\n"interaction.c_max" = { uniform = [0.1, 0.2] }\n', "cases"),
    "cases too many": (SWEEP + 'cases = 2000000\n[random]\n"interaction.c_max" = { uniform = [0.1, 0.2] }\n', "cases"),
    "seed negative": (SWEEP.replace('"s"', '"s"\nseed = -1'), "seed"),
    "batch zero": (SWEEP + "batch = 0\n", "batch"),
    "unknown metric": (SWEEP + 'metrics = ["speed"]\n', "metrics"),
    "metric twice": (SWEEP + 'metrics = ["coupled", "coupled"]\n', "metrics"),
    "empty grid": (SWEEP + '[grid]\n"interaction.c_max" = []\n', "grid.interaction.c_max"),
    "grid not a list": (SWEEP + '[grid]\n"interaction.c_max" = 0.1\n', "grid.interaction.c_max"),
    "unknown path": (SWEEP + '[grid]\n"interaction.cmax" = [0.1, 0.2]\n', "interaction.cmax"),
    "value the scenario refuses": (SWEEP + '[grid]\n"interaction.c_max" = [0.1, -0.2]\n', "interaction.c_max"),
    "coarse dt in a grid": (SWEEP + '[grid]\n"simulation.dt" = [0.0001, 0.05]\n', "simulation.dt"),
    "path given twice": (SWEEP + '[set]\n"interaction.c_max" = 0.1\n[grid]\n"interaction.c_max" = [0.1, 0.2]\n',
                         "grid.interaction.c_max"),
    "result column as a path": (SWEEP + '[grid]\n"case" = [1, 2]\n', "grid.case"),
    "unknown key": (SWEEP + "colour = 1\n", "colour"),
    "no base": ('name = "s"\n', "base"),
    "unknown base": ('base = "fig99"\n', "base"),
    "missing base file": ('base = "nowhere.toml"\n', "nowhere.toml"),
    "deep nesting": (SWEEP + "x = " + "[" * 3000 + "]" * 3000 + "\n", "nested too deeply"),
    "syntax": (SWEEP + "cases = = 2\n", "TOML syntax error"),
    "set refused": (SWEEP + '[set]\n"interaction.radius" = -1.0\n', "interaction.radius"),
}


@pytest.mark.parametrize("name", SWEEP_CASES, ids=list(SWEEP_CASES))
def test_bad_sweep(name, tmp_path, runner):
    text, field = SWEEP_CASES[name]
    (tmp_path / "bad.toml").write_text(text)
    out = tmp_path / "out"
    result = runner.invoke(app, ["sweep", str(tmp_path / "bad.toml"), "--out", str(out)])
    _assert_refused(result, field, out, {"bad.toml"}, tmp_path)


# -- animate ----------------------------------------------------------------------------------------------

ANIMATE_CASES = {
    "missing run": (lambda d: ["animate", str(d / "nowhere")], "nowhere: no such folder"),
    "empty folder": (lambda d: (d / "empty").mkdir() or ["animate", str(d / "empty")], "empty"),
    "a file for the run": (lambda d: (d / "afile").write_text("x") and ["animate", str(d / "afile")], "afile"),
    "fps zero": (lambda d: ["animate", str(d / "nowhere"), "--fps", "0"], "--fps: must be at least 1, got 0"),
    "fps negative": (lambda d: ["animate", str(d / "nowhere"), "--fps", "-3"], "--fps: must be at least 1, got -3"),
    "max_frames zero": (lambda d: ["animate", str(d / "nowhere"), "--max-frames", "0"], "--max-frames: must be at least 1"),
    "max_frames negative": (lambda d: ["animate", str(d / "nowhere"), "--max-frames", "-1"], "--max-frames: must be"),
}


@pytest.mark.parametrize("name", ANIMATE_CASES, ids=list(ANIMATE_CASES))
def test_bad_animate(name, tmp_path, runner):
    make, field = ANIMATE_CASES[name]
    args = make(tmp_path)
    before = {p.name for p in tmp_path.iterdir()}
    out = tmp_path / "movie.gif"
    result = runner.invoke(app, [*args, "--out", str(out)])
    _assert_refused(result, field, out, before, tmp_path)


def test_the_battery_is_large():
    assert len(CASES) + len(SWEEP_CASES) + len(ANIMATE_CASES) + 2 * len(SPECIAL) + 2 >= 150
