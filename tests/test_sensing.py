"""Sensing and communication: each effect against an independent reference.

The pair runs are Fig. 9 at dt = 0.01 s, every step recorded.  A pair's recorded ``|d|``
(``interaction_distance``) is the one its first agent (agent 0) measured, so it is compared with
``P*`` (6) computed here from the recorded true states: the noise's statistics against the set
standard deviations (normal and chi-square bounds), the delay against the trajectory ``tau``
earlier, the loss against the binomial law, the range against the pushes that reach an agent.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

import tmem
from tmem.law.modal import interaction_point
from tmem.law.interaction import evaluate
from tmem.scenario import with_changes

#: Bounds of the statistical checks: a two-sided level of 1e-6 (about 4.9 standard deviations).
LEVEL = 1e-6
Z = stats.norm.isf(LEVEL / 2)


def pair_run(sensing: dict, duration: float = 30.0) -> tmem.Trajectory:
    """Fig. 9 at dt = 0.01 s with the ``[sensing]`` table ``sensing``, every step recorded."""
    base = with_changes(tmem.preset("fig9"), {"simulation.dt": 0.01, "simulation.duration": duration,
                                             "simulation.record_every": 1})  # fmt: skip
    return tmem.simulate(with_changes(base, {"sensing": sensing}))


def stars(tr: tmem.Trajectory) -> np.ndarray:
    """True ``P*`` (6) of each recorded agent at each step, shape (steps, agents) (one axis)."""
    return interaction_point(tr.state[:, :, 0, :], tr.gains)


def measured_d(tr: tmem.Trajectory) -> np.ndarray:
    """Agent 0's measured ``P*_1 - P*_0``, signed as the true one (the agents never pass each other)."""
    true = stars(tr)[:, 1] - stars(tr)[:, 0]
    assert np.all(np.abs(true) > 25.0)
    return tr.interaction_distance[:, 0] * np.sign(true)


def held_message(tr: tmem.Trajectory) -> np.ndarray:
    """The step each of agent 0's measurements of agent 1 was sent at, found by matching the measured
    ``d`` with ``P*_1(s) - P*_0(k)`` from the trajectory (noise off); -1 where it measured nothing."""
    p = stars(tr)
    d = measured_d(tr)
    sent = np.full(len(d), -1)
    for k in range(len(d)):
        if np.isnan(d[k]):
            continue
        match = np.flatnonzero(np.abs(p[: k + 1, 1] - p[k, 0] - d[k]) < 1e-9)
        assert len(match) == 1, (k, match)
        sent[k] = match[0]
    return sent


@pytest.mark.unit
def test_the_hash_is_splitmix64():
    """The compiled hash against a pure-Python SplitMix64 (Vigna's splitmix64.c): its first output
    from state 0 is the published 0xE220A8397B1DCDAF, and a draw is the chain over its five numbers."""
    from tmem.world.streams import message_key, mix, uniform

    mask = 2**64 - 1

    def reference(z: int) -> int:
        z = (z + 0x9E3779B97F4A7C15) & mask
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & mask
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & mask
        return z ^ (z >> 31)

    assert reference(0) == 0xE220A8397B1DCDAF
    rng = np.random.default_rng(3)
    for z in [0, 1, mask, *rng.integers(0, 2**63, 20).tolist()]:
        assert int(mix(np.uint64(z))) == reference(z)
    for seed, receiver, sender, step, draw in [(0, 0, 0, 0, 0), (7, 3, 11, 123456, 5), (2**62, 18, 0, 10**9, 2)]:
        h = reference(seed)
        for value in (receiver, sender, step, draw):
            h = reference((h + value) & mask)
        key = np.uint64(message_key(seed, receiver, sender, step))  # from Python an int: as the loop types it
        assert uniform(key, draw) == ((h >> 11) + 0.5) / 2**53


@pytest.mark.unit
def test_normal_draws_are_standard_normal_and_independent():
    """100 000 pairs of draws over steps and senders: each draw's mean, variance (chi-square) and
    Kolmogorov-Smirnov test against the normal law, and no correlation within a pair, between
    pairs of one message, or between neighbouring steps."""
    from tmem.world.streams import message_key, normal_pair

    n = 100_000
    keys = [np.uint64(message_key(5, 2, 1 + k % 7, k)) for k in range(n)]
    first, second = np.array([normal_pair(key, 1) for key in keys]).T
    other = np.array([normal_pair(key, 2)[0] for key in keys])
    for x in (first, second):
        assert abs(x.mean()) < Z / np.sqrt(n)
        chi2 = (n - 1) * x.var(ddof=1)
        assert stats.chi2.ppf(LEVEL / 2, n - 1) < chi2 < stats.chi2.isf(LEVEL / 2, n - 1)
        assert stats.kstest(x, "norm").pvalue > LEVEL
    for a, b in ((first, second), (first, other), (first[1:], first[:-1])):
        assert abs(np.corrcoef(a, b)[0, 1]) < Z / np.sqrt(n)


@pytest.mark.parametrize("sensing", [{"position_noise": 0.3, "velocity_noise": 0.2},
                                     {"own_position_noise": 0.4, "own_velocity_noise": 0.5}],
                         ids=["neighbour", "own"])  # fmt: skip
def test_measured_minus_true_has_the_set_noise(sensing):
    """``d`` measured less ``d`` true is the noise on ``P*_1`` less the noise on ``P*_0``:
    ``n_P + (K_V / K_P) n_V`` for each, so its variance is ``s_P^2 + (K_V / K_P)^2 s_V^2`` summed
    over the noises set; mean 0, chi-square bounds on the variance, and white from step to step."""
    tr = pair_run(sensing)
    true = stars(tr)[:, 1] - stars(tr)[:, 0]
    error = measured_d(tr) - true
    c = tr.gains[1] / tr.gains[0]
    sigma2 = sum(sensing.get(f"{who}position_noise", 0.0) ** 2 + (c * sensing.get(f"{who}velocity_noise", 0.0)) ** 2
                 for who in ("", "own_"))  # fmt: skip
    n = len(error)
    assert abs(error.mean()) < Z * np.sqrt(sigma2 / n)
    chi2 = (n - 1) * error.var(ddof=1) / sigma2
    assert stats.chi2.ppf(LEVEL / 2, n - 1) < chi2 < stats.chi2.isf(LEVEL / 2, n - 1)
    assert abs(np.corrcoef(error[1:], error[:-1])[0, 1]) < Z / np.sqrt(n)


@pytest.mark.parametrize("delay,lag", [(0.03, 3), (0.035, 4), (0.0301, 4)])
def test_each_agent_acts_on_its_neighbour_tau_earlier(delay, lag):
    """With a delay and no noise, agent 0 measures ``P*_1`` ``lag = ceil(tau / dt)`` steps earlier
    (the latest broadcast at or before ``t - tau``, the start before it), and agent 1 ``P*_0`` so;
    each one's recorded push is the function (11) at its own ``d``: the two are not opposite."""
    tr = pair_run({"delay": delay})
    p = stars(tr)
    earlier = lambda agent, by: p[np.maximum(np.arange(len(p)) - by, 0), agent]  # noqa: E731
    np.testing.assert_allclose(measured_d(tr), earlier(1, lag) - p[:, 0], rtol=0, atol=1e-9)
    assert np.abs(measured_d(tr) - (earlier(1, lag - 1) - p[:, 0])).max() > 1e-3  # one step less does not fit
    ia = tr.scenario.interaction
    push = lambda d: evaluate("improved", d, tr.flag[:, 0], k_p=tr.gains[0], reach=ia.reach, d_t=ia.d_t, c_max=ia.c_max)  # noqa: E731
    np.testing.assert_allclose(tr.control[:, 0, 0], push(earlier(1, lag) - p[:, 0]), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(tr.control[:, 1, 0], -push(p[:, 1] - earlier(0, lag)), rtol=1e-9, atol=1e-12)
    assert np.abs(tr.control[:, 0, 0] + tr.control[:, 1, 0]).max() > 1e-4


def test_messages_sent_once_a_period_are_held_between():
    """A message every 5 steps (0.05 s) arriving 4 steps late (0.035 s): agent 0 knows ``P*_1`` of the
    latest multiple of 5 steps at or before ``k - 4``."""
    tr = pair_run({"period": 0.05, "delay": 0.035})
    p = stars(tr)
    sent = np.maximum((np.arange(len(p)) - 4) // 5 * 5, 0)
    np.testing.assert_allclose(measured_d(tr), p[sent, 1] - p[:, 0], rtol=0, atol=1e-9)


def test_a_random_delay_uses_the_newest_message_that_arrived():
    """Delays uniform on [0.02, 0.06] s at dt = 0.01 s: a message is usable after 3, 4, 5 or 6 steps,
    each with probability 1/4, and the newest usable one is held.  Its age is then 3, 4, 5 or 6 steps
    with probabilities 1/4, 3/8, 9/32 and 3/32 (the first of the messages 3, 4, ... steps old that has
    arrived), and a receiver never goes back to an older message."""
    tr = pair_run({"delay": [0.02, 0.06]})
    sent = held_message(tr)[10:]
    assert np.all(np.diff(sent) >= 0)
    age = np.arange(10, 10 + len(sent)) - sent
    expected = np.array([8, 12, 9, 3]) / 32
    found = np.array([np.mean(age == a) for a in (3, 4, 5, 6)])
    assert found.sum() == 1.0
    # Ages at neighbouring steps share messages; the bound allows them a variance three times the binomial's.
    assert np.all(np.abs(found - expected) < Z * np.sqrt(3 * expected * (1 - expected) / len(age))), found


def test_a_lost_message_leaves_the_last_one_held():
    """Loss 0.3 without delay: at each step agent 0 holds the step's message, or, when it was lost,
    the one it held before (its age growing); the share lost is within binomial bounds of 0.3."""
    tr = pair_run({"loss": 0.3})
    sent = held_message(tr)
    k = np.arange(len(sent))
    fresh = sent == k
    assert np.all(fresh | (sent == np.concatenate([[0], sent[:-1]])))
    lost = 1.0 - fresh[1:].mean()
    assert abs(lost - 0.3) < Z * np.sqrt(0.3 * 0.7 / (len(sent) - 1)), lost


def test_a_held_message_keeps_its_noise_and_expires_after_the_hold():
    """Loss L = 0.7, noise on positions, a hold of 2 steps: agent 0 holds the newest of the last three
    messages it got, and measures nothing when all three were lost (a share of L^3).  The ``P*_1`` it
    knows keeps the same bits while it holds a message, its noise included.  Between two steps at
    which it measured, it holds the same message when the step's message was lost: a share of
    L (1 - L^2) / ((1 - L)(1 - L^3) + L (1 - L^2)), about 0.644."""
    loss = 0.7
    tr = pair_run({"loss": loss, "position_noise": 0.5, "hold": 0.02})
    known = measured_d(tr) + stars(tr)[:, 0]  # P*_1 as agent 0 knows it (its own state is exact)
    heard = ~np.isnan(known)
    both = heard[1:] & heard[:-1]
    unchanged = np.abs(np.diff(known))[both] < 1e-9
    held = loss * (1 - loss**2) / ((1 - loss) * (1 - loss**3) + loss * (1 - loss**2))
    # Neighbouring steps share messages: the bounds allow a variance several times the binomial's.
    assert abs(unchanged.mean() - held) < Z * np.sqrt(3 * held * (1 - held) / both.sum()), unchanged.mean()
    assert abs((~heard).mean() - loss**3) < Z * np.sqrt(5 * loss**3 * (1 - loss**3) / len(heard)), (~heard).mean()


def line_of_agents(n: int, gap: float, sensing: dict) -> tmem.Trajectory:
    """``n`` agents at rest on a line: agents 0 and 1 ``gap`` apart, the others 1000 m apart; one step."""
    agents = [{"position": 0.0}, {"position": gap}] + [{"position": 1000.0 * (k + 1)} for k in range(n - 2)]
    return tmem.simulate(tmem.scenario.from_dict({"interaction": {"function": "repulsion"}, "agents": agents,
                                                  "sensing": sensing,
                                                  "simulation": {"dt": 0.01, "duration": 0.01, "record_every": 1}}))  # fmt: skip


@pytest.mark.parametrize("n", [2, 40], ids=["pair", "neighbours"])
def test_no_push_from_beyond_the_range(n):
    """Two agents 35 m apart, within reach (40 m) of each other: beyond a range of 30 m neither pushes
    the other; within a range of 36 m each gets the repulsion (8), as a pair (2 agents) and as
    neighbours (40 agents, past the tracked pairs)."""
    far = line_of_agents(n, 35.0, {"range": 30.0})
    assert np.all(far.control[0] == 0.0)
    near = line_of_agents(n, 35.0, {"range": 36.0})
    expected = evaluate("repulsion", 35.0, k_p=near.gains[0], reach=40.0, d_t=35.0, c_max=0.1)
    assert expected < 0.0
    np.testing.assert_allclose(near.control[0, :2, 0], [expected, -expected], rtol=1e-12)
    assert np.all(near.control[0, 2:] == 0.0)
