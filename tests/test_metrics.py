"""Metrics on hand-made trajectories whose answers are known by construction."""

import numpy as np
import pytest

import tmem
from tmem.engine import Event, Trajectory
from tmem.analysis.metrics import nearest_distance, pair_summary, rms_velocity, summarize
from tmem.world.initial import build
from tmem.vehicles import vehicle_model


def made(distance, flag, events, velocities=None):
    """A two-agent trajectory on one axis: agent 0 at 0, agent 1 at ``distance``."""
    scenario = tmem.preset("fig9")
    n = len(distance)
    state = np.zeros((n, 2, 1, 4))
    state[:, 1, 0, 0] = distance
    if velocities is not None:
        state[:, :, 0, 1] = velocities
    return Trajectory(
        scenario=scenario,
        initial=build(scenario),
        model=vehicle_model(scenario.model),
        gains=np.ones(4),
        time=np.arange(n, dtype=float),
        agents=np.array([0, 1]),
        state=state,
        control=np.zeros((n, 2, 1)),
        active=np.ones((n, 2), dtype=bool),
        flag=np.asarray(flag)[:, None],
        pair_distance=np.asarray(distance, dtype=float)[:, None],
        interaction_distance=np.asarray(distance, dtype=float)[:, None],
        min_distance=np.array([min(distance)]),
        min_neighbor_distance=np.inf,
        final_state=state[-1],
        final_active=np.ones(2, dtype=bool),
        events=events,
        list_builds=0,
        gas=np.zeros((n, 0)),
    )


def test_pair_summary_of_a_known_oscillation():
    #        t = 0   1   2   3   4   5   6   7   8
    distance = [50, 36, 33, 37, 33, 36, 39, 41, 60]
    flag = [0, 1, 1, 1, 1, 0, 0, 0, 0]
    events = [Event(1.0, "couple", (0, 1)), Event(3.0, "command", (0, 1), "uncouple"), Event(5.0, "uncouple", (0, 1))]
    s = pair_summary(made(distance, flag, events), 0)
    assert s["coupled_at"] == 1.0 and s["uncoupled_at"] == 5.0
    assert s["separated_at"] == 7.0  # first time at or beyond R + R_j = 40 m after uncoupling
    assert s["oscillation_amplitude"] == pytest.approx((37 - 33) / 2)
    assert s["mean_distance_coupled"] == pytest.approx((36 + 33 + 37 + 33) / 4)
    errors = np.array([1, 2, 2, 2])  # |distance - 35| while coupled
    assert s["distance_error"]["max"] == 2 and s["distance_error"]["mean"] == pytest.approx(errors.mean())
    assert s["distance_error"]["rms"] == pytest.approx(np.sqrt(np.mean(errors**2)))
    assert s["min_distance"] == 33 and s["final_distance"] == 60


def test_never_coupled_pair_has_no_coupling_figures():
    s = pair_summary(made([60, 50, 45, 50], [0, 0, 0, 0], []), 0)
    assert s["coupled_at"] is None and s["separated_at"] is None and s["oscillation_amplitude"] is None


def test_summary_rms_change_from_known_speeds():
    tr = made([50, 50], [0, 0], [], velocities=np.array([[3.0, -1.5], [3.0, -1.5]]))
    s = summarize(tr)
    # The setup holds Table 2's start, (-1.5, 3.0); the end speeds here are (3, -1.5): the same RMS.
    assert s["rms_velocity_initial"] == pytest.approx(np.sqrt((1.5**2 + 3**2) / 2))
    assert s["rms_change_percent"] == pytest.approx(0.0, abs=1e-12)


def test_rms_velocity_counts_only_active_agents():
    v = np.array([[[3.0, 4.0], [0.0, 0.0], [6.0, 8.0]]])  # speeds 5, 0, 10
    assert rms_velocity(v)[0] == pytest.approx(np.sqrt((25 + 0 + 100) / 3))
    assert rms_velocity(v, np.array([[True, False, True]]))[0] == pytest.approx(np.sqrt((25 + 100) / 2))


def test_nearest_distance_matches_brute_force_in_a_periodic_box():
    rng = np.random.default_rng(2)
    box = np.array([100.0, 80.0])
    points = rng.uniform(0, 1, (200, 2)) * box
    active = rng.uniform(size=200) > 0.2
    delta = points[active][:, None] - points[active][None, :]
    delta -= box * np.round(delta / box)
    brute = np.linalg.norm(delta, axis=2)
    np.fill_diagonal(brute, np.inf)
    assert nearest_distance(points, active, box) == pytest.approx(brute.min(), rel=1e-12)
    assert nearest_distance(points, active, np.zeros(2)) >= brute.min()


def started_coupled(trajectory):
    """The same trajectory, its pair coupled from the start (as a formation's pairs are)."""
    import dataclasses

    initial = dataclasses.replace(trajectory.initial, flag=np.ones_like(trajectory.initial.flag))
    return dataclasses.replace(trajectory, initial=initial)


# (distance, flag, events, started coupled) -> (coupled, at start, ever, at end, couple_time, uncouple_time)
COUPLING = {
    "never": ([60, 50, 45, 50], [0, 0, 0, 0], [], False, (False, 0, 0, 0, None, None)),
    "Table 2 pair, uncoupled by command": (
        [50, 36, 33, 41], [0, 1, 1, 0],
        [Event(1.0, "couple", (0, 1)), Event(2.0, "command", (0, 1), "uncouple"), Event(3.0, "uncouple", (0, 1))],
        False, (True, 0, 1, 0, 1.0, 3.0),
    ),
    "Table 2 pair, no command": ([50, 36, 33, 36], [0, 1, 1, 1], [Event(1.0, "couple", (0, 1))], False,
                                 (True, 0, 1, 1, 1.0, None)),
    "formation pair, coupled throughout": ([35, 36, 34, 35], [1, 1, 1, 1], [], True, (True, 1, 1, 1, 0.0, None)),
    "formation pair losing an agent": ([35, 36, 34, 35], [1, 1, 0, 0], [Event(2.0, "uncouple", (0, 1))], True,
                                       (True, 1, 1, 0, 0.0, 2.0)),
}  # fmt: skip


@pytest.mark.parametrize("case", COUPLING, ids=list(COUPLING))
def test_coupled_means_coupled_at_any_time_including_from_the_start(case):
    distance, flag, events, start, expected = COUPLING[case]
    tr = made(distance, flag, events)
    s = summarize(started_coupled(tr) if start else tr)
    keys = ("coupled", "pairs_coupled_at_start", "pairs_coupled_ever", "pairs_coupled_at_end", "couple_time", "uncouple_time")
    assert tuple(s[k] for k in keys) == expected
    assert s["pairs"][0]["coupled_at"] == expected[4] and s["pairs"][0]["coupled_at_end"] == bool(expected[3])
    # The RMS change is flagged exactly when pairs are still coupled at the end.
    assert s["rms_change_while_coupled"] is bool(expected[3])


def test_every_agent_gone_gives_null_not_inf_or_nan():
    """summary.json stays valid JSON: null where a figure does not exist."""
    import dataclasses
    import json

    tr = made([50, 50], [0, 0], [], velocities=np.array([[3.0, -1.5], [3.0, -1.5]]))
    tr = dataclasses.replace(tr, final_active=np.zeros(2, dtype=bool), min_distance=np.array([np.inf]))
    s = summarize(tr)
    assert s["rms_velocity_final"] is None and s["rms_change_percent"] is None  # not -100 %: no agent flies
    assert s["min_distance"] is None and s["pairs"][0]["min_distance"] is None and s["final_distance"] is None
    json.dumps(s, allow_nan=False)


@pytest.mark.interface
def test_table_marks_an_rms_change_taken_while_coupled():
    from rich.console import Console

    from tmem.cli.terminal import SWINGS, summary_table

    rows = {}
    for name, (distance, flag, events, start, _) in COUPLING.items():
        tr = made(distance, flag, events, velocities=np.array([[-1.5, 3.0]] * len(distance)))
        rows[name] = summarize(started_coupled(tr) if start else tr)
    console = Console(width=300, record=True)
    console.print(summary_table(rows))
    text = console.export_text()
    lines = {name: next(line for line in text.splitlines() if name in line) for name in rows}
    assert " no " in lines["never"] and "yes, 1/1 at end" in lines["formation pair, coupled throughout"]
    assert "yes, 0/1 at end" in lines["formation pair losing an agent"]
    assert " * " in lines["Table 2 pair, no command"] and " * " not in lines["Table 2 pair, uncoupled by command"]
    # Coupled at the end but 1 m off d_t a record before: still oscillating, so marked.
    assert " * " in lines["formation pair, coupled throughout"]
    assert SWINGS in " ".join(text.split())


def _held(n=40, swing=0.0):
    """A formation pair coupled throughout, 1 s between records, at d_t = 35 m but for ``swing`` m
    off it over the first 10 s."""
    distance = np.full(n, 35.0)
    distance[:10] += swing * np.sin(np.arange(10))
    return summarize(started_coupled(made(list(distance), [1] * n, [], velocities=np.array([[-1.5, 3.0]] * n))))


def test_a_pair_held_at_its_distance_does_not_swing():
    """The settled pair's RMS change is not marked; one off by 0.5 m over its last 20 s is."""
    assert _held()["rms_change_while_coupled"] is True and _held()["rms_change_swings"] is False
    assert _held(swing=1.0)["rms_change_swings"] is False  # only in its first 10 s of 40
    assert _held(n=25, swing=1.0)["rms_change_swings"] is True  # within its last 20 s


def test_a_synchronised_formation_is_not_marked_as_swinging_in_the_table():
    """The settled triangle (synchronised) holds its pairs within 0.1 m over its last 20 s: its ΔRMS is
    a settled value, not marked; the same triangle unsynchronised keeps oscillating and is marked."""
    from rich.console import Console

    from tmem.cli.terminal import SWINGS, summary_table
    from tmem.scenario import load, with_changes

    settled = load(tmem.__path__[0] + "/../../examples/swarm/triangle_settled.toml")
    runs = {"settled": settled, "free": with_changes(settled, {"interaction.synchronise": False})}
    rows = {name: summarize(tmem.simulate(scenario)) for name, scenario in runs.items()}
    for s in rows.values():  # independent of the summary: the recorded distances over the last 20 s
        assert s["rms_change_while_coupled"] is True
    assert rows["settled"]["rms_change_swings"] is False and rows["free"]["rms_change_swings"] is True
    console = Console(width=300, record=True)
    console.print(summary_table({"settled": rows["settled"]}))
    assert " * " not in console.export_text() and SWINGS not in " ".join(console.export_text().split())
    console.print(summary_table(rows))
    assert SWINGS in " ".join(console.export_text().split())


@pytest.mark.parametrize("width", [60, 80, 100, 300])
def test_the_table_never_folds_a_name_or_a_number(width):
    """On any terminal width, every run's name and every figure is printed whole on one line."""
    from rich.console import Console

    from tmem.cli.terminal import summary_table

    tr = made([50, 36, 33, 36], [0, 1, 1, 1], [Event(1.0, "couple", (0, 1))], velocities=np.array([[-1.5, 3.0]] * 4))
    s = summarize(tr)
    names = ["hex19-settled", "gas-box in a walled box, thermostat at 2 m/s", "fig9-energy"]
    console = Console(width=width, record=True)
    console.print(summary_table({name: s for name in names}))
    lines = console.export_text().splitlines()
    assert all(len(line.rstrip()) <= width for line in lines)
    for text in [*names, "yes, 1/1 at end", f"{s['rms_change_percent']:+.3f} *", "largest ΔRMS (%)"]:
        assert sum(text in line for line in lines) >= 1, (text, width)


def test_summary_gives_the_largest_rms_change_on_the_way_and_when():
    """Speeds known by construction: Table 2's start (RMS 2.37 m/s), then both agents at 3.0, 1.2, 2.5 m/s."""
    start = np.sqrt((1.5**2 + 3.0**2) / 2)
    speeds = np.array([start, 3.0, 1.2, 2.5])
    velocities = np.column_stack([speeds, -speeds])
    velocities[0] = (-1.5, 3.0)
    tr = made([50, 50, 50, 50], [0, 0, 0, 0], [], velocities=velocities)
    s = summarize(tr)
    changes = 100 * (speeds / start - 1)  # +26.5 %, -49.4 %, +5.4 %
    assert s["rms_change_peak_percent"] == pytest.approx(changes[2]) and s["rms_change_peak_time"] == 2.0
    assert s["rms_change_percent"] == pytest.approx(changes[3])


@pytest.mark.physics
@pytest.mark.parametrize("kind, n", [("triangle", None), ("chain", 4), ("ring", 6)])
def test_formations_report_coupled_from_the_start_and_after_a_loss(kind, n):
    """A formation starts coupled (no couple event) and a ring losing an agent keeps the rest."""
    from tmem.scenario import from_dict

    formation = {"kind": kind, "velocity": [3.0, 0.0], "jitter": 1.0, "seed": 1} | ({"n": n} if n else {})
    data = {"space": {"axes": 2}, "interaction": {"function": "improved"}, "formation": formation,
            "simulation": {"duration": 3.0}}  # fmt: skip
    if kind == "ring":
        data["commands"] = [{"time": 1.0, "action": "remove", "agent": 2}]
    tr = tmem.simulate(from_dict(data))
    s = summarize(tr)
    n_pairs = len(tr.pairs)
    lost = 2 if kind == "ring" else 0
    assert (s["coupled"], s["couple_time"]) == (True, 0.0)
    assert (s["pairs_coupled_at_start"], s["pairs_coupled_ever"], s["pairs_coupled_at_end"]) == (n_pairs, n_pairs, n_pairs - lost)
    assert s["pairs_coupled_at_end"] == int(np.sum(tr.flag[-1] == 1))  # the last record is the end
    assert s["uncouple_time"] == (pytest.approx(1.0) if lost else None)
    assert s["rms_change_while_coupled"] is True


@pytest.mark.interface
def test_the_table2_pair_left_coupled_is_flagged_in_summary_and_table(tmp_path):
    """Without its uncouple command the pair is still coupled at the end: its RMS change is marked as swinging."""
    import json

    from typer.testing import CliRunner

    from tmem.cli.main import app
    from tmem.cli.terminal import SWINGS

    text = tmem.preset("fig9").to_toml().split("[[commands]]")[0]
    text = text.replace("duration = 60.0", "duration = 6.0").replace("dt = 0.0001", "dt = 0.001")
    (tmp_path / "coupled.toml").write_text(text)
    result = CliRunner().invoke(app, ["run", str(tmp_path / "coupled.toml"), "--out", str(tmp_path / "o")], env={"COLUMNS": "200"})
    assert result.exit_code == 0, result.output
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert s["coupled"] and s["pairs_coupled_at_end"] == 1 and s["rms_change_while_coupled"] is True
    assert "yes, 1/1 at end" in result.stdout and f"{s['rms_change_percent']:+.3f} *" in result.stdout
    assert SWINGS in " ".join(result.stdout.split())
