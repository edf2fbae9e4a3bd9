"""Swarms in 2-D and 3-D: equivalence with the paper's 1-D run, neighbour lists, formations, loss."""

import numpy as np
import pytest

import tmem
from tmem.engine import driver as engine
from tmem.engine import lists
from tmem.engine.lists import _partners
from tmem.analysis.metrics import summarize
from tmem.world.neighbors import arrange, verlet_pairs
from tmem.scenario import from_dict, with_changes


def rotated(preset: str, direction: np.ndarray) -> tmem.Scenario:
    """The preset's two agents moved onto the line through the origin along ``direction``."""
    base = tmem.preset(preset)
    data = base.model_dump()
    data["space"] = {"axes": len(direction)}
    data["agents"] = [
        {"position": (a.position * direction).tolist(), "velocity": (a.velocity * direction).tolist()}
        for a in base.agents
    ]
    return from_dict(data)


@pytest.mark.parametrize("preset", ["repulsion", "fig5", "fig7", "fig9"])
@pytest.mark.parametrize(
    "direction",
    [np.array([1.0, 0.0]), np.array([0.6, -0.8]), np.array([2.0, 3.0, 6.0]) / 7.0],
    ids=["2d-x", "2d-oblique", "3d-oblique"],
)
def test_motion_on_a_line_equals_the_1d_run(preset, direction):
    one = tmem.simulate(tmem.preset(preset))
    many = tmem.simulate(rotated(preset, direction))
    along = np.einsum("tiam,a->tim", many.state, direction)
    # Error relative to each component's scale over the run.  An oblique line rounds differently
    # from the x axis at every one of the 600 000 steps; measured: P and V within 1.3e-10, the tilt
    # and tilt rate (driven through the saturation at every step) within 3.3e-9.
    ref = one.state[:, :, 0, :]
    scale = np.abs(ref).max(axis=(0, 1))
    across = many.state - along[:, :, None, :] * direction[None, None, :, None]
    for error in (np.abs(along - ref).max(axis=(0, 1)) / scale, np.abs(across).max(axis=(0, 1, 2)) / scale):
        assert np.all(error[:2] < 1e-9), error
        assert np.all(error[2:] < 1e-8), error
    assert [(e.time, e.kind) for e in many.events] == [(e.time, e.kind) for e in one.events]


def random_swarm(n: int, axes: int, periodic: bool, method: str, steps: int = 300) -> tmem.Scenario:
    side = np.sqrt(n * np.pi * 40.0**2 / 6) if axes == 2 else (n * 4 / 3 * np.pi * 40.0**3 / 6) ** (1 / 3)
    return from_dict(
        {
            "interaction": {"function": "repulsion"},
            "space": {"axes": axes, "periodic": periodic, "box": [side] * axes},
            "swarm": {"n": n, "seed": 7, "speed_rms": 3.0},
            "neighbors": {"method": method, "skin": 2.0},
            "simulation": {"dt": 0.01, "duration": steps * 0.01, "record_every": 50},
        }
    )


@pytest.mark.parametrize("axes,periodic", [(2, False), (2, True), (3, True)])
def test_verlet_lists_give_the_same_bits_as_all_pairs(axes, periodic):
    """Verlet lists and every pair give the same bits: the product's claim (docs/swarms.md), so bit
    for bit: each agent's pushes are summed in the same order either way."""
    a = tmem.simulate(random_swarm(500, axes, periodic, "all"))
    b = tmem.simulate(random_swarm(500, axes, periodic, "verlet"))
    assert b.list_builds > 1  # the lists were rebuilt along the way
    assert a.final_state.tobytes() == b.final_state.tobytes()
    assert np.abs(a.final_state).max() > 0 and a.min_neighbor_distance == b.min_neighbor_distance


@pytest.mark.slow  # the plain threaded loop is compiled for this test alone: see below
def test_threaded_loop_gives_the_same_bits_as_the_serial_one(monkeypatch):
    """Threads give the serial loop's bits, the product's claim (docs/swarms.md), in blocks of 32.
    In the default run tests/test_gas.py checks the claim on the threaded loop with the gas's
    stages, in blocks too; this one is the plain swarm's."""
    monkeypatch.setattr(lists, "BLOCK", 32)  # several blocks, summed on both threads
    monkeypatch.setattr(engine, "THREADED_SWARM", 100)
    scenario = random_swarm(200, 2, True, "verlet")
    threaded = tmem.simulate(scenario)
    monkeypatch.setattr(engine, "THREADED_SWARM", 10**9)
    serial = tmem.simulate(scenario)
    assert threaded.final_state.tobytes() == serial.final_state.tobytes()


@pytest.mark.parametrize("axes", [2, 3])
def test_blocks_keep_verlet_lists_and_all_pairs_equal(monkeypatch, axes):
    """With small blocks many pairs cross between blocks; every agent's sum must still be the same
    with either kind of list (the product's claim, bit for bit), and close to the one-block sum
    (another order of the same terms)."""
    monkeypatch.setattr(lists, "BLOCK", 64)
    a = tmem.simulate(random_swarm(500, axes, True, "all", steps=100))
    b = tmem.simulate(random_swarm(500, axes, True, "verlet", steps=100))
    assert a.final_state.tobytes() == b.final_state.tobytes()
    monkeypatch.setattr(lists, "BLOCK", 4096)
    one = tmem.simulate(random_swarm(500, axes, True, "verlet", steps=100))
    assert one.final_state.tobytes() != b.final_state.tobytes()  # the order did change
    # the tolerance allowed for another summation order; measured after 100 steps: 3.4e-15 at most
    np.testing.assert_allclose(b.final_state, one.final_state, rtol=0, atol=1e-12)


@pytest.mark.unit
@pytest.mark.parametrize("parts", [1, 3])
@pytest.mark.parametrize("axes,periodic", [(1, False), (2, False), (2, True), (3, False), (3, True)])
def test_verlet_pairs_match_brute_force(axes, periodic, parts):
    rng = np.random.default_rng(axes)
    n, side, cutoff = 400, 200.0, 44.0
    points = rng.uniform(0, side, (n, axes))
    active = rng.uniform(size=n) > 0.1
    box = (side,) * axes if periodic else (0.0,) * axes
    small = np.empty((0, 2), dtype=np.uint32)
    needed, room = verlet_pairs(points, active, cutoff, box, small, np.empty((2, 1), dtype=np.int32), parts)
    pairs = np.empty((needed, 2), dtype=np.uint32)
    found = np.empty((2, room), dtype=np.int32)
    assert verlet_pairs(points, active, cutoff, box, pairs, found, parts) == (needed, room)
    delta = points[None, :, :] - points[:, None, :]
    if periodic:
        delta -= side * np.round(delta / side)
    close = (np.linalg.norm(delta, axis=2) < cutoff) & active[None, :] & active[:, None]
    expected = np.argwhere(np.triu(close, k=1))  # (i, j), i < j, sorted by i then j
    assert needed > n  # the test sees many pairs
    assert pairs.tolist() == expected.tolist()


@pytest.mark.unit
def test_arrange_drops_formation_pairs_and_cuts_blocks():
    n, block = 10, 4
    pairs = np.array([(i, j) for i in range(n) for j in range(i + 1, n)], dtype=np.uint32)
    partners = np.array([[1, 2], [2, 9]])
    adj_ptr, adj_idx = _partners(n, partners)
    block_ptr = np.empty(n // block + 2, dtype=np.int64)
    inside, kept = arrange(pairs, len(pairs), adj_ptr, adj_idx, block, block_ptr)
    expected_inside = [(i, j) for i in range(n) for j in range(i + 1, n) if i // block == j // block]
    expected_inside.remove((1, 2))
    expected_crossing = [(i, j) for i in range(n) for j in range(i + 1, n) if i // block != j // block]
    expected_crossing.remove((2, 9))
    assert pairs[:inside].tolist() == [list(p) for p in expected_inside]
    assert pairs[inside:kept].tolist() == [list(p) for p in expected_crossing]
    firsts = pairs[:inside, 0] // block
    assert block_ptr.tolist() == np.searchsorted(firsts, np.arange(len(block_ptr))).tolist()


def test_periodic_gas_keeps_momentum_and_stays_in_the_box():
    """Pushes across the box edge are equal and opposite too.  With several neighbours, saturating
    an agent's summed set-point breaks that symmetry, so c_max is set too high to saturate here."""
    tr = tmem.simulate(with_changes(random_swarm(300, 2, True, "auto"), {"interaction.c_max": 10.0}))
    side = tr.initial.box[0]
    p0 = tr.initial.state[:, :, 1].sum(axis=0)
    np.testing.assert_allclose(tr.final_state[:, :, 1].sum(axis=0), p0, atol=1e-9)
    assert np.all((tr.final_state[:, :, 0] >= 0) & (tr.final_state[:, :, 0] < side))


def formation(kind: str, n: int | None = None, **extra) -> tmem.Scenario:
    data = {
        "space": {"axes": 2},
        "interaction": {"function": "improved"},
        "formation": {"kind": kind, "velocity": [3.0, 0.0], "jitter": 1.0, "seed": 3, **({"n": n} if n else {})},
        "simulation": {"dt": 1e-4, "duration": 60.0},
    }
    data.update(extra)
    return from_dict(data)


@pytest.mark.parametrize("kind,n", [("triangle", None), ("hex", 19), ("chain", 5), ("ring", 6)])
def test_formation_keeps_its_shape_while_flying(kind, n):
    """Started 1 m off its places at 3 m/s, the formation flies 60 s with every pair within 2 m of d_t."""
    tr = tmem.simulate(formation(kind, n))
    s = summarize(tr)
    assert s["formation"]["coupled_at_end"] == 1.0
    assert s["formation"]["distance_error"]["max"] < 2.0
    # It really flew: the centre moved 180 m along x.
    centre = tr.state[:, :, :, 0].mean(axis=1)
    np.testing.assert_allclose(centre[-1] - centre[0], [180.0, 0.0], atol=0.5)


def test_held_directions_keep_the_formation_from_turning():
    tr = tmem.simulate(formation("hex", 7, formation={"kind": "hex", "n": 7, "bearing": True, "velocity": [3.0, 1.0],
                                                         "jitter": 1.0, "seed": 3}))  # fmt: skip
    s = summarize(tr)
    assert s["formation"]["direction_error_deg"] < 5.0
    assert s["formation"]["distance_error"]["max"] < 2.0


@pytest.mark.parametrize("kind,n,lost", [("ring", 8, 3), ("hex", 19, 0)])
def test_formation_survives_the_loss_of_an_agent(kind, n, lost):
    s = formation(kind, n, commands=[{"time": 20.0, "action": "remove", "agent": lost}])
    tr = tmem.simulate(s)
    others = [p for p, (i, j) in enumerate(tr.pairs.tolist()) if lost not in (i, j)]
    theirs = [p for p in range(len(tr.pairs)) if p not in others]
    after = tr.time > 20.0
    assert np.all(tr.flag[after][:, others] == 1)  # the rest keep their pairs ...
    assert np.all(tr.flag[after][:, theirs] == 0)  # ... the lost agent's pairs are gone
    error = np.abs(tr.pair_distance[after][:, others] - tr.d_t[others])
    assert error.max() < 2.0  # ... and hold their distances
    q = list(tr.agents).index(lost)
    assert not tr.active[after, q].any()
    stopped = tr.state[after, q, :, 0]
    assert np.all(stopped == stopped[0])  # it stopped where it was lost


def test_added_agent_starts_from_its_entry():
    s = from_dict(
        {
            "space": {"axes": 2},
            "interaction": {"function": "repulsion"},
            "agents": [
                {"position": [0.0, 0.0], "velocity": [1.0, 0.0]},
                {"position": [0.0, 100.0]},
                {"position": [50.0, 50.0], "velocity": [0.0, -2.0], "active": False},
            ],
            "commands": [{"time": 5.0, "action": "add", "agent": 2}],
            "simulation": {"duration": 10.0},
        }
    )
    tr = tmem.simulate(s)
    k = np.searchsorted(tr.time, 5.0)
    assert not tr.active[k - 1, 2] and tr.active[k, 2]
    np.testing.assert_allclose(tr.state[k, 2, :, 0], [50.0, 50.0])
    np.testing.assert_allclose(tr.state[-1, 2, :, 0], [50.0, 40.0], atol=1e-9)
    assert [e.action for e in tr.events] == ["add"] and tr.events[0].agents == (2,)


def test_uncouple_a_listed_set_of_pairs():
    s = formation("chain", 4, commands=[{"time": 10.0, "action": "uncouple", "pairs": [[0, 1], [2, 3]]}])
    tr = tmem.simulate(s)
    released = {tuple(e.agents) for e in tr.events if e.kind == "uncouple"}
    assert released == {(0, 1), (2, 3)}
    assert tr.flag[-1].tolist() == [0, 1, 0]


def test_recording_a_subset_of_agents():
    """Recording some agents records their rows of the same run, bit for bit: what is recorded
    never changes what is computed."""
    s = with_changes(random_swarm(100, 2, True, "auto"), {"simulation.record_agents": [3, 50, 7]})
    tr = tmem.simulate(s)
    full = tmem.simulate(random_swarm(100, 2, True, "auto"))
    assert tr.state.shape[1] == 3 and tr.agents.tolist() == [3, 50, 7]
    np.testing.assert_array_equal(tr.state, full.state[:, [3, 50, 7]])


def test_sparse_periodic_swarm_lists_every_neighbour_once():
    """Few agents in a big periodic box: the cell grid is capped, and must never leave 2 cells round an
    axis; the lists then give the same bits as every pair (the product's claim)."""
    s = from_dict(
        {
            "interaction": {"function": "repulsion"},
            "space": {"axes": 3, "periodic": True, "box": [500.0, 500.0, 500.0]},
            "swarm": {"n": 40, "seed": 1, "speed_rms": 3.0, "region": [60.0, 60.0, 60.0]},
            "simulation": {"dt": 0.01, "duration": 20.0, "record_every": 100},
        }
    )
    a = tmem.simulate(with_changes(s, {"neighbors.method": "all"}))
    b = tmem.simulate(with_changes(s, {"neighbors.method": "verlet"}))
    assert a.final_state.tobytes() == b.final_state.tobytes()


def test_recording_no_agents_keeps_the_pairs():
    tr = tmem.simulate(formation("triangle", None, simulation={"duration": 2.0, "record_agents": []}))
    assert tr.state.shape[1] == 0 and tr.flag.shape == (len(tr.time), 3)


def test_direction_error_across_a_periodic_edge():
    """A chain flying across the box edge keeps its bearing; the error must use the nearest image."""
    s = from_dict(
        {
            "space": {"axes": 2, "periodic": True, "box": [200.0, 200.0]},
            "interaction": {"function": "improved"},
            "formation": {"kind": "chain", "n": 3, "bearing": True, "center": [150.0, 100.0], "velocity": [3.0, 0.0]},
            "simulation": {"duration": 30.0},
        }
    )
    assert summarize(tmem.simulate(s))["formation"]["direction_error_deg"] < 1.0


def test_losing_an_agent_uncouples_its_pairs_as_events():
    tr = tmem.simulate(formation("ring", 6, commands=[{"time": 5.0, "action": "remove", "agent": 2}]))
    lost = sorted(e.agents for e in tr.events if e.kind == "uncouple")
    assert lost == [(1, 2), (2, 3)] and all(e.time == pytest.approx(5.0) for e in tr.events)


@pytest.mark.parametrize("function", tmem.FUNCTION_NAMES)
@pytest.mark.parametrize("n_agents", [2, 32, 34, 80])
def test_a_pair_feels_its_function_whatever_the_size_of_the_swarm(function, n_agents):
    """Two agents at rest 30 m apart (d_t = 35 m) and the others far away: the first set-point on agent 0
    is the function's value at |d| = 30 m, whether the pair is tracked one by one (small swarms, coupling
    functions) or summed among the neighbours (flagless functions beyond 32 agents, by all pairs or by
    Verlet lists).  Unsaturated (c_max = 1 rad), attraction gives K_P (30 - 35) < 0; with d_t lost on
    one path it gave K_P 30 > 0."""
    agents = [{"position": 0.0}, {"position": 30.0}] + [{"position": 1000.0 + 100.0 * k} for k in range(n_agents - 2)]
    scenario = from_dict({
        "interaction": {"function": function, "c_max": 1.0, "d_t": 35.0},
        "simulation": {"dt": 0.01, "duration": 0.1, "record_every": 1},
        "agents": agents,
    })  # fmt: skip
    tr = tmem.simulate(scenario)
    k_p = tr.gains[0]
    expected = tmem.law.interaction.evaluate(function, 30.0, 0, k_p=k_p, reach=40.0, d_t=35.0, c_max=1.0)
    assert tr.control[0, 0, 0] == pytest.approx(float(expected), rel=1e-12)
    assert tr.control[0, 1, 0] == pytest.approx(-float(expected), rel=1e-12)
    if function == "attraction":
        assert expected == pytest.approx(k_p * (30.0 - 35.0))
