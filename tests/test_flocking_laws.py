"""The flocking laws as agent terms (tmem.terms.olfati_saber, tmem.terms.vasarhelyi) against the papers.

"OS": R. Olfati-Saber, IEEE TAC 51(3), 2006; "VV": G. Vásárhelyi et al., Science Robotics 3(20),
2018 (docs/flocking_laws.md).  The references here are written from the papers' equations in plain
Python (math, no tmem function): the scalar functions at chosen points, each law's push on a few
agents with walls and an obstacle, and runs of the linear model (2) under exact knowledge.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import pytest

import tmem
from tmem.scenario import ScenarioError, from_dict, with_changes
from tmem.terms import term_class

EPS, H, A, B = 0.1, 0.2, 5.0, 5.0  # OS, Section VIII


def os_sigma(r, eps=EPS):  # OS 8, literally
    return (math.sqrt(1 + eps * r * r) - 1) / eps


def os_rho(z, h):  # OS 10
    if 0 <= z < h:
        return 1.0
    if h <= z <= 1:
        return 0.5 * (1 + math.cos(math.pi * (z - h) / (1 - h)))
    return 0.0


def os_phi(z, a, b):  # OS 15
    c = abs(a - b) / math.sqrt(4 * a * b)
    s = (z + c) / math.sqrt(1 + (z + c) ** 2)
    return 0.5 * ((a + b) * s + (a - b))


def os_phi_alpha(z, r, d, h=H, a=A, b=B):  # OS 15-16, with r_α = |r|_σ, d_α = |d|_σ
    return os_rho(z / os_sigma(r), h) * os_phi(z - os_sigma(d), a, b)


def os_phi_beta(z, d_prime, h):  # OS, Section VII
    d_beta = os_sigma(d_prime)
    return os_rho(z / d_beta, h) * ((z - d_beta) / math.sqrt(1 + (z - d_beta) ** 2) - 1)


def vv_braking(r, a, p):  # VV, the braking curve D
    if r <= 0:
        return 0.0
    return r * p if r * p < a / p else math.sqrt(2 * a * r - a * a / (p * p))


def test_sigma_norm_bump_and_action_functions_are_the_papers():
    from tmem.terms import flocking as f

    for r in (0.0, 1e-6, 0.3, 7.0, 8.4, 40.0, 1e4):
        assert f.sigma_norm(r, EPS) == pytest.approx(os_sigma(r), rel=1e-12, abs=1e-15)
    assert f.sigma_norm(3e-5, 1e-6) == pytest.approx(0.5 * 3e-5**2, rel=1e-9)  # the literal form loses it to cancellation
    h = 0.2
    for z in (-0.1, 0.0, h / 2, h - 1e-12, h, 0.5, 0.9, 1.0 - 1e-12, 1.0, 1.0 + 1e-12, 3.0):
        assert f.bump(z, h) == pytest.approx(os_rho(z, h), abs=1e-15)
    assert f.bump(h, h) == 1.0 and f.bump(1.0, h) == 0.0  # the switch points: 1 at h, 0 at 1, exactly
    for a, b in ((5.0, 5.0), (1.0, 5.0), (2.0, 3.0)):
        for z in (-30.0, -1.0, 0.0, 0.4, 2.0, 30.0):
            assert f.action(z, a, b) == pytest.approx(os_phi(z, a, b), abs=1e-12)
        assert abs(f.action(0.0, a, b)) < 1e-14  # c makes φ(0) = 0
        assert f.action(-1e6, a, b) == pytest.approx(-b, rel=1e-6) and f.action(1e6, a, b) == pytest.approx(a, rel=1e-6)


@pytest.mark.parametrize("a,b", [(5.0, 5.0), (1.0, 5.0)])
def test_phi_alpha_vanishes_at_r_and_changes_sign_at_d(a, b):
    from tmem.terms import flocking as f

    d, r = 7.0, 8.4
    r_alpha, d_alpha = os_sigma(r), os_sigma(d)
    assert f.phi_alpha(r_alpha, r_alpha, d_alpha, H, a, b) == 0.0  # exactly: ρ_h(1) = 0
    assert f.phi_alpha(2 * r_alpha, r_alpha, d_alpha, H, a, b) == 0.0
    assert f.phi_alpha(d_alpha - 1e-3, r_alpha, d_alpha, H, a, b) < 0.0 < f.phi_alpha(d_alpha + 1e-3, r_alpha, d_alpha, H, a, b)
    for z in np.linspace(0.0, 1.2 * r_alpha, 37):
        assert f.phi_alpha(z, r_alpha, d_alpha, H, a, b) == pytest.approx(os_phi_alpha(z, r, d, H, a, b), abs=1e-12)
        assert f.phi_beta(z, os_sigma(4.2), 0.9) == pytest.approx(os_phi_beta(z, 4.2, 0.9), abs=1e-12)


def test_braking_curve_is_continuous_at_its_switch_and_the_papers_elsewhere():
    from tmem.terms import flocking as f

    a, p = 2.5, 0.4
    switch = a / p**2  # r p = a / p
    for r in (-1.0, 0.0, 0.5, switch - 1e-9, switch, switch + 1e-9, 40.0, 1e3):
        assert f.braking(r, a, p) == pytest.approx(vv_braking(r, a, p), rel=1e-12, abs=1e-15)
    assert f.braking(switch, a, p) == pytest.approx(a / p, rel=1e-12)


class Agents(NamedTuple):
    """What a term's kernel reads of the loop's Agents."""

    setpoint: np.ndarray
    active: np.ndarray


BOX, OBSTACLE = [60.0, 50.0], ([30.0, 30.0], 4.0)
POSITIONS = np.array([[10.0, 10.0], [16.5, 11.0], [12.0, 4.0], [33.0, 24.0]])
VELOCITIES = np.array([[1.0, 0.5], [-0.5, 2.0], [0.2, -1.0], [-1.5, 3.0]])


def scenario_with(table: str, settings: dict, c_max: float = 0.5):
    agents = [{"position": p.tolist(), "velocity": v.tolist()} for p, v in zip(POSITIONS, VELOCITIES)]
    return from_dict({
        "space": {"axes": 2, "walls": True, "box": BOX},
        "interaction": {"function": "none", "c_max": c_max, "radius": 0.5, "d_t": 0.5, "eps": 0.1},
        "simulation": {"dt": 0.01, "duration": 1.0}, "agents": agents,
        "obstacles": [{"center": OBSTACLE[0], "radius": OBSTACLE[1]}], table: settings,
    })  # fmt: skip


def kernel_pushes(scenario, name: str) -> np.ndarray:
    """Every agent's set-point from the term's compiled kernel alone, on the scenario's starts."""
    term = term_class(name)
    record = term.record(getattr(scenario, name), scenario, None)
    known = np.zeros((len(POSITIONS), 2, 4))
    known[:, :, 0], known[:, :, 1] = POSITIONS, VELOCITIES
    agents = Agents(np.zeros((len(POSITIONS), 2)), np.ones(len(POSITIONS), dtype=np.bool_))
    push = term.kernel()
    for i in range(len(POSITIONS)):
        push(i, 0, known, agents, (0.0, 0.0), record)
    return agents.setpoint


def saturated(u, limit):
    size = np.linalg.norm(u)
    return u * min(1.0, limit / size) if size > 0 else u


def os_push(i, s, g=9.8, c_max=0.5):
    """u_i of OS 24 with the β-agents of Algorithm 3, from the paper, over the walls of BOX and OBSTACLE."""
    q, p = POSITIONS, VELOCITIES
    d, r, dp = s["d"], s["kappa"] * s["d"], s["beta_ratio"] * s["d"]
    u = -s["c1"] * (q[i] - np.array(s["q_r"])) - s["c2"] * (p[i] - np.array(s["p_r"]))
    for j in range(len(q)):
        z = os_sigma(np.linalg.norm(q[j] - q[i]))
        if j != i and z < os_sigma(r):
            n_ij = (q[j] - q[i]) / math.sqrt(1 + EPS * np.linalg.norm(q[j] - q[i]) ** 2)
            u = u + os_phi_alpha(z, r, d) * n_ij + os_rho(z / os_sigma(r), H) * (p[j] - p[i])
    hats = []
    for axis in range(2):  # a wall: the hyperplane's β-agent, q̂ = P q + (I - P) y, p̂ = P p
        for wall in (0.0, BOX[axis]):
            projector = np.eye(2) - np.outer(np.eye(2)[axis], np.eye(2)[axis])
            hats.append((projector @ q[i] + (np.eye(2) - projector) @ np.array([wall, wall]), projector @ p[i]))
    y, radius = np.array(OBSTACLE[0]), OBSTACLE[1]
    mu, a_k = radius / np.linalg.norm(q[i] - y), (q[i] - y) / np.linalg.norm(q[i] - y)
    hats.append((mu * q[i] + (1 - mu) * y, mu * (np.eye(2) - np.outer(a_k, a_k)) @ p[i]))
    for q_hat, p_hat in hats:
        z = os_sigma(np.linalg.norm(q_hat - q[i]))
        n_hat = (q_hat - q[i]) / math.sqrt(1 + EPS * np.linalg.norm(q_hat - q[i]) ** 2)
        b_ik = os_rho(z / os_sigma(dp), 0.9)
        u = u + s["c1_beta"] * os_phi_beta(z, dp, 0.9) * n_hat + s["c2_beta"] * b_ik * (p_hat - p[i])
    return saturated(u / g, c_max)


def test_the_olfati_saber_kernel_pushes_as_the_paper_on_four_agents_walls_and_an_obstacle():
    settings = {"d": 7.0, "kappa": 1.2, "beta_ratio": 0.6, "c1_beta": 3.0, "c2_beta": 2.0, "c1": 0.3, "c2": 0.7,
                "q_r": [20.0, 15.0], "p_r": [0.5, -0.2]}  # fmt: skip
    ours = kernel_pushes(scenario_with("olfati_saber", settings), "olfati_saber")
    full = {"eps": EPS, **settings}
    expected = np.array([os_push(i, full) for i in range(len(POSITIONS))])
    np.testing.assert_allclose(ours, expected, rtol=1e-10, atol=1e-13)
    assert np.abs(expected[0] - os_push(0, {**full, "c1": 0.0, "c2": 0.0})).max() > 0.01  # the γ-agent acts
    alone = np.array([os_push(i, {**full, "c1_beta": 0.0, "c2_beta": 0.0}) for i in range(len(POSITIONS))])
    assert np.all(np.abs(alone[2:] - expected[2:]).max(axis=1) > 1e-3)  # the wall at y = 0 acts on 2, the obstacle on 3


def vv_push(i, s, g=9.8, c_max=0.5):
    """VV's desired velocity for agent i over BOX's walls and OBSTACLE, through robotsim's velocity loop, as a tilt."""
    q, p = POSITIONS, VELOCITIES
    v_d = s["v_flock"] * p[i] / np.linalg.norm(p[i])
    for j in range(len(q)):
        r_ij, v_ij = np.linalg.norm(q[i] - q[j]), np.linalg.norm(p[i] - p[j])
        if j == i or r_ij >= s["r_c"]:
            continue
        if r_ij < s["r0_rep"]:
            v_d = v_d + s["p_rep"] * (s["r0_rep"] - r_ij) * (q[i] - q[j]) / r_ij
        v_max_ij = max(s["v_frict"], vv_braking(r_ij - s["r0_frict"], s["a_frict"], s["p_frict"]))
        if v_ij > v_max_ij:
            v_d = v_d + s["c_frict"] * (v_ij - v_max_ij) * (p[j] - p[i]) / v_ij
    shills = [(q[i][axis] - wall if wall == 0.0 else wall - q[i][axis], np.eye(2)[axis] * (1 if wall == 0.0 else -1))
              for axis in range(2) for wall in (0.0, BOX[axis])]  # fmt: skip
    y, radius = np.array(OBSTACLE[0]), OBSTACLE[1]
    shills.append((np.linalg.norm(q[i] - y) - radius, (q[i] - y) / np.linalg.norm(q[i] - y)))
    for r_is, normal in shills:
        v_s = s["v_shill"] * normal
        v_is = np.linalg.norm(v_s - p[i])
        v_max_is = vv_braking(r_is - s["r0_shill"], s["a_shill"], s["p_shill"])
        if v_is > v_max_is:
            v_d = v_d + (v_is - v_max_is) * (v_s - p[i]) / v_is
    v_d = saturated(v_d, s["v_max"])
    return saturated(saturated((v_d - p[i]) / s["tau"], s["a_max"]) / g, c_max)


@pytest.mark.parametrize("c_max", [0.5, 0.05])
def test_the_vasarhelyi_kernel_pushes_as_the_paper_on_four_agents_walls_and_an_obstacle(c_max):
    settings = {"r0_rep": 8.0, "p_rep": 0.5, "r0_frict": 3.0, "c_frict": 0.3, "v_frict": 0.4, "p_frict": 0.8,
                "a_frict": 1.5, "r0_shill": 0.5, "v_shill": 5.0, "p_shill": 0.6, "a_shill": 2.0, "r_c": 20.0,
                "tau": 0.8, "a_max": 9.0}  # fmt: skip
    ours = kernel_pushes(scenario_with("vasarhelyi", settings, c_max), "vasarhelyi")
    full = {**term_class("vasarhelyi").table().model_dump(), **settings}
    expected = np.array([vv_push(i, full, c_max=c_max) for i in range(len(POSITIONS))])
    np.testing.assert_allclose(ours, expected, rtol=1e-10, atol=1e-13)
    assert np.linalg.norm(ours, axis=1).max() == pytest.approx(c_max) if c_max < 1 else np.all(np.linalg.norm(ours, axis=1) < 1)


PAIR = """
[space]
axes = 2
[interaction]
function = "none"
c_max = 0.3
[simulation]
dt = 0.001
duration = 8.0
record_every = 10
[[agents]]
position = [0.0, 0.0]
[[agents]]
position = [{start}, 0.0]
[olfati_saber]
d = 7.0
"""


def pair_distance(trajectory) -> np.ndarray:
    return np.linalg.norm(trajectory.state[:, 1, :, 0] - trajectory.state[:, 0, :, 0], axis=1)


def lattice_loop(k_rel: float, c_rel: float, g: float = 9.8, kp: float = 6.0, kd: float = 25.0) -> np.ndarray:
    """The eigenvalues of a pair's relative motion on the model (2), pushed by ``-k_rel s - c_rel s'`` (m/s^2)."""
    a = np.array([[0, 1, 0, 0], [0, 0, g, 0], [0, 0, 0, 1], [0, 0, -kp * kd, -kd]], dtype=float)
    return np.linalg.eigvals(a - np.outer([0, 0, 0, kp * kd], [k_rel / g, c_rel / g, 0, 0]))


#: The pair's stiffness and damping at |q_j - q_i| = d from OS 23: each agent is pushed by φ_α n_ij (slope
#: ρ_h(d_α / r_α) (a + b) / 2 in σ, times (dσ/dr)^2 = d^2 / (1 + ε d^2)) and damped by a_ij.
A_IJ = os_rho(os_sigma(7.0) / os_sigma(8.4), H)
K_PAIR = A_IJ * 0.5 * (A + B) * 49.0 / (1 + EPS * 49.0)


def test_the_alpha_lattice_pair_oscillates_with_the_growth_the_tilting_vehicle_gives_it():
    """OS 23 alone on the model (2): the tilt loop's lag undamps the pair, which the paper's double
    integrator would not; the growth is the linearised loop's, within 5 % (dt = 1 ms adds a lag of
    dt / 2 to the tilt loop's sixth of a second)."""
    growth = max(lattice_loop(2 * K_PAIR, 2 * A_IJ).real)
    assert growth > 0.5
    error = pair_distance(tmem.simulate(tmem.loads(PAIR.format(start=7.00005)))) - 7.0
    period = 2 * math.pi / max(lattice_loop(2 * K_PAIR, 2 * A_IJ).imag)
    steps = round(period / 0.01)  # records 10 ms apart
    early, late = (start + int(np.argmax(np.abs(error[start : start + steps]))) for start in (100, 600))  # a peak each
    assert math.log(abs(error[late] / error[early])) / ((late - early) * 0.01) == pytest.approx(growth, rel=0.05)


def test_the_alpha_lattice_pair_settles_at_d_with_the_gamma_agents_damping():
    """With the γ-agent (OS 24) damping at c2 = 6 /s (its pull c1 = 0.1 /s^2 towards the midpoint), the
    loop is stable (slowest decay about 1.1 /s, from the linearisation), and the pair settles where
    c1 s / 2 = -φ_α(|s|_σ) s / sqrt(1 + ε s^2): short of d by about c1 d / (2 K), K the stiffness above."""
    assert max(lattice_loop(2 * K_PAIR + 0.1, 2 * A_IJ + 6.0).real) < -1.0
    scenario = tmem.loads(PAIR.format(start=6.9) + "c1 = 0.1\nc2 = 6.0\nq_r = [3.45, 0.0]\n")
    trajectory = tmem.simulate(with_changes(scenario, {"simulation.dt": 0.005}))

    def balance(s: float) -> float:
        return 0.05 * s + os_phi_alpha(os_sigma(s), 8.4, 7.0) * s / math.sqrt(1 + EPS * s * s)

    low, high = 6.5, 7.0  # balance < 0 below the equilibrium, > 0 above it
    for _ in range(60):
        low, high = (low, (low + high) / 2) if balance((low + high) / 2) > 0 else ((low + high) / 2, high)
    assert 7.0 - low == pytest.approx(0.1 * 7.0 / (2 * K_PAIR), rel=0.1)  # to first order: φ_α curves by 6 % over it
    # 8 s at a decay of 1.1 /s leave 1.5e-4 of the start's 0.05 m: well inside 1e-4 m.
    assert pair_distance(trajectory)[-1] == pytest.approx(low, abs=1e-4)
    assert np.abs(trajectory.state[-1, :, :, 1]).max() < 1e-4


def vasarhelyi_pair(duration: float = 20.0):
    """Two agents 30 m apart closing at 1.5 m/s under [vasarhelyi], its alignment 20 times robotsim's."""
    scenario = tmem.loads(PAIR.replace("[olfati_saber]\nd = 7.0\n", "[vasarhelyi]\nc_frict = 0.5\n").format(start=30.0))
    agents = [{"position": [0.0, 0.0], "velocity": [0.0, 4.0]}, {"position": [30.0, 0.0], "velocity": [-1.5, 4.0]}]
    return with_changes(scenario, {"agents": agents, "simulation.duration": duration, "simulation.dt": 0.01})


def test_the_vasarhelyi_pair_keeps_apart_and_aligns():
    """Two agents 30 m apart closing at 1.5 m/s (alignment made 20 times robotsim's, c_frict = 0.5, so that
    it acts within the run): the repulsion stops them short of r0_rep by less than the closing speed
    undone at its slope (w / (2 p_rep)) plus what the velocity loop lets through (w tau); the alignment
    leaves them a velocity difference of at most v_frict, so the order |û_i + û_j| / 2 is at least
    sqrt(1 - (v_frict / (2 v))^2) for speeds v."""
    trajectory = tmem.simulate(vasarhelyi_pair())
    s = trajectory.scenario.vasarhelyi
    distance, velocity = pair_distance(trajectory), trajectory.state[:, :, :, 1]
    assert distance.min() > s.r0_rep - 1.5 / (2 * s.p_rep) - 1.5 * s.tau
    speeds = np.linalg.norm(velocity[-1], axis=1)
    headings = velocity[-1] / speeds[:, None]
    assert np.linalg.norm(velocity[-1, 1] - velocity[-1, 0]) < s.v_frict + 1e-6
    assert np.ptp(speeds) < 1e-6  # the bound below is for equal speeds: it moves by about that much
    assert np.linalg.norm(headings.sum(axis=0)) / 2 >= math.sqrt(1 - (s.v_frict / (2 * speeds.min())) ** 2) - 1e-6
    assert speeds == pytest.approx(s.v_flock, rel=1e-6)


@pytest.mark.parametrize(("table", "changes", "field", "reason"), [
    ("olfati_saber", {"kappa": 1.0}, "olfati_saber.kappa", "greater than 1"),
    ("olfati_saber", {"d": -7.0}, "olfati_saber.d", "greater than 0"),
    ("olfati_saber", {"a": 6.0}, "olfati_saber.a", "exceeds b = 5"),
    ("olfati_saber", {"h_beta": 1.0}, "olfati_saber.h_beta", "less than 1"),
    ("olfati_saber", {"c1": 1.0}, "olfati_saber.q_r", "is required with c1 = 1"),
    ("olfati_saber", {"q_r": [1.0]}, "olfati_saber.q_r", "needs 2 values"),
    ("vasarhelyi", {"v_flock": 9.0}, "vasarhelyi.v_flock", "exceeds v_max = 8"),
    ("vasarhelyi", {"r_c": 20.0}, "vasarhelyi.r0_rep", "not less than the communication range"),
    ("vasarhelyi", {"tau": 1e-3}, "vasarhelyi.tau", "shorter than the step"),
    ("vasarhelyi", {"c_frict": 1.5}, "vasarhelyi.c_frict", "less than or equal to 1"),
    ("vasarhelyi", {"r0_shill": -1.0}, "vasarhelyi.r0_shill", "greater than or equal to 0"),
    ("olfati_saber", {"route": [[0.0, 0.0], [50.0, 0.0]]}, "olfati_saber.route_speed", "is required with a route of 2 points"),
    ("olfati_saber", {"route": [[0.0, 0.0]], "q_r": [1.0, 1.0]}, "olfati_saber.q_r", "is not used with a route"),
    ("vasarhelyi", {"route": [[0.0, 0.0, 1.0]]}, "vasarhelyi.route[0]", "needs 2 values"),
    ("vasarhelyi", {"route_speed": 2.0}, "vasarhelyi.route_speed", "is not used without a route"),
])  # fmt: skip
def test_bad_parameters_are_refused_in_one_line(table, changes, field, reason):
    with pytest.raises(ScenarioError) as error:
        scenario_with(table, changes)
    line = str(error.value)
    assert "\n" not in line and line.startswith(f"{field}: ") and reason in line, line


def test_sensing_between_agents_is_refused_and_own_noise_is_not():
    scenario = scenario_with("vasarhelyi", {})
    scenario = with_changes(scenario, {"obstacles": [], "space.walls": False})
    with_changes(scenario, {"sensing": {"own_position_noise": 0.1}})
    with pytest.raises(ScenarioError, match=r"^sensing\.delay: 0\.2 acts on what agents measure of each other"):
        with_changes(scenario, {"sensing": {"delay": 0.2}})


def test_a_flocking_run_goes_on_from_its_checkpoint_to_the_same_bits(tmp_path):
    """The terms' records are fixed for the run or written before they are read each step: nothing to save."""
    from test_checkpoint import assert_same_bits, stopped_after

    from tmem.engine.checkpoint import Checkpoints

    scenario = vasarhelyi_pair(6.0)
    saved = stopped_after(scenario, tmp_path / "run.npz", 2.0, 4.0)
    assert not [key for key in saved.arrays if key.startswith("terms.")]
    assert_same_bits(tmem.simulate(scenario), tmem.simulate(scenario, checkpoints=Checkpoints(tmp_path / "run.npz", 2.0)))


ROUTE = [[0.0, 0.0], [30.0, 0.0], [30.0, 40.0]]


@pytest.mark.parametrize(("t", "where", "velocity"), [
    (0.0, (0.0, 0.0), (5.0, 0.0)), (3.0, (15.0, 0.0), (5.0, 0.0)), (8.0, (30.0, 10.0), (0.0, 5.0)),
    (14.0, (30.0, 40.0), (0.0, 0.0)), (60.0, (30.0, 40.0), (0.0, 0.0)),
])  # fmt: skip
def test_the_moving_reference_flies_its_route_at_its_speed_and_holds_the_end(t, where, velocity):
    """Against the arc length written here: 5 m/s along 30 m then 40 m, held from 14 s on."""
    from tmem.terms.flocking import leader, route_record

    route, lengths = route_record(ROUTE, 2)
    for a in range(2):
        assert leader(t, route, lengths, 5.0, a) == pytest.approx((where[a], velocity[a]), abs=1e-12)


def two_agents(table: str, settings: dict, duration: float, second: list[float]):
    return tmem.simulate(from_dict({
        "space": {"axes": 2}, "interaction": {"function": "none", "c_max": 0.5, "radius": 0.5, "d_t": 0.5, "eps": 0.1},
        "simulation": {"dt": 0.01, "duration": duration, "record_every": 10},
        "agents": [{"position": [0.0, 0.0]}, {"position": second}], table: settings,
    }))  # fmt: skip


def test_the_olfati_saber_gamma_agent_leads_a_pair_along_its_route():
    """Two agents under OS 23-24 with a reference flying a straight line at 4 m/s: the γ-agent's feedback
    has the reference's velocity as its feed-forward and the α-forces cancel in the pair's mean, so the
    pair's centre ends on the reference, moving with it, its agents where the α-force (OS 23) balances
    the γ-agent's pull c1 r/2 on each (a little inside the lattice's d = 7 m), solved here by brentq."""
    from scipy.optimize import brentq

    trajectory = two_agents("olfati_saber", {"c1": 0.5, "c2": 3.0, "route": [[0.0, 20.0], [2000.0, 20.0]],
                                             "route_speed": 4.0}, 120.0, [10.0, 0.0])
    q, v = trajectory.state[-1, :, :, 0], trajectory.state[-1, :, :, 1]
    assert q.mean(axis=0) == pytest.approx([4.0 * 120.0, 20.0], abs=0.01)
    assert v == pytest.approx(np.array([[4.0, 0.0], [4.0, 0.0]]), abs=0.01)
    balance = brentq(lambda r: os_phi_alpha(os_sigma(r), 8.4, 7.0) / math.sqrt(1 + EPS * r * r) * r + 0.5 * r / 2, 3.0, 7.0)
    assert balance < 6.9  # the pull moves it: the test tells the balance from d
    assert np.linalg.norm(q[1] - q[0]) == pytest.approx(balance, abs=0.01)


def test_the_vasarhelyi_goal_draws_an_agent_at_the_flocking_speed():
    """SwarmLab's goal mode: v_d = v_flock towards the goal, so mid-way the agent flies at v_flock straight at it."""
    trajectory = two_agents("vasarhelyi", {"route": [[300.0, 400.0]]}, 60.0, [-500.0, -500.0])  # beyond r_c
    r = np.searchsorted(trajectory.time, 40.0)
    q, v = trajectory.state[r, 0, :, 0], trajectory.state[r, 0, :, 1]
    assert np.linalg.norm(v) == pytest.approx(4.0, rel=1e-3)
    assert v / np.linalg.norm(v) == pytest.approx([0.6, 0.8], abs=1e-3)
    assert np.linalg.norm(q) == pytest.approx(4.0 * 40.0, abs=6.0)  # it did fly there: less the velocity loop's start
