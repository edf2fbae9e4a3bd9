"""The worked extensions of docs/architecture.md, carried out on a copy of the package and run.

Each extension is a list of edits (old text, new text), each naming the file it touches; the test
applies them to a copy of ``src/tmem``, runs a scenario with the copy in a fresh interpreter, and
checks the outcome against a closed form.  The files touched are counted here and in
docs/architecture.md: the test fails if an extension needs more files than the page says.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

SOURCE = Path(__file__).resolve().parents[1] / "src" / "tmem"

#: (file, old text, new text) for each extension: what a contributor would edit.
EXTENSIONS = {
    "interaction function": [
        ("law/interaction/kernels.py", "def _dispatch(rows)", textwrap.dedent('''\
            @numba.njit(cache=True, inline="always")
            def plateau(r, f_en, p):
                """A toy function: a constant push of c_max / 2 inside the spheres, 0 outside."""
                return -0.5 * p.c_max if r < p.reach else 0.0


            def _dispatch(rows)''')),
        ("law/interaction/registry.py", "\n)  # fmt: skip", textwrap.dedent('''
                InteractionFunction(
                    "plateau", "plateau", "none (a toy)", couples=False, continuous=False,
                    summary="c_max / 2 apart inside the spheres, 0 outside",
                ),
            )  # fmt: skip''')),
    ],
    "vehicle model": [
        ("vehicles/drag.py", "", textwrap.dedent('''\
            """A toy vehicle: the linear model (2) with drag on the velocity, V' = g phi - c_d V."""

            from typing import Literal

            from tmem.scenario.fields import Positive
            from tmem.vehicles.linear import LinearModel, LinearModelParams, state_matrices


            class DragModelParams(LinearModelParams):
                """The linear model's table with drag: ``[model] kind = "drag"``."""

                kind: Literal["drag"] = "drag"
                c_d: Positive = 0.5


            class DragModel(LinearModel):
                kind = "drag"
                table = DragModelParams

                def linearisation(self):
                    a, b = state_matrices(self.params.kp, self.params.kd, self.params.g)
                    a[1, 1] = -self.params.c_d
                    return a, b
            ''')),
        ("vehicles/__init__.py", '    "linear": ("tmem.vehicles.linear:LinearModel", "tmem.vehicles.linear:LinearModelParams"),\n',
         '    "linear": ("tmem.vehicles.linear:LinearModel", "tmem.vehicles.linear:LinearModelParams"),\n'
         '    "drag": ("tmem.vehicles.drag:DragModel", "tmem.vehicles.drag:DragModelParams"),\n'),
    ],
    "sensing effect": [
        ("world/sensing.py", "    work: np.ndarray\n", "    work: np.ndarray\n    quantum: float = 0.0\n"),
        ("world/sensing.py", "            out[row, a, 1] += sensing.velocity_noise * noise_v\n",
         "            out[row, a, 1] += sensing.velocity_noise * noise_v\n"
         "        if sensing.quantum > 0.0:  # quantised: positions known to the nearest multiple of quantum\n"
         "            out[row, a, 0] = np.round(out[row, a, 0] / sensing.quantum) * sensing.quantum\n"),
    ],
    "agent term": [
        ("terms/shove.py", "", textwrap.dedent('''\
            """A toy agent term: a constant push along the first axis, U_i += level (S)."""

            from functools import cache
            from typing import NamedTuple

            from tmem.scenario.fields import Number, StrictModel
            from tmem.terms.base import AgentTerm


            class ShoveParams(StrictModel):
                level: Number


            class Shoved(NamedTuple):
                level: float


            def _push(i, k, known, agents, box, shove):
                agents.setpoint[i, 0] += shove.level


            class Shove(AgentTerm):
                name = "shove"
                table = ShoveParams
                rebuilt = {"level": "a number fixed for the run"}

                @classmethod
                def record(cls, settings, scenario, gains):
                    return Shoved(float(settings.level))

                @classmethod
                @cache
                def kernel(cls):
                    import numba

                    return numba.njit(inline="always")(_push)
            ''')),
        ("terms/__init__.py", '    "pull": "tmem.terms.pull:Pull",\n', '    "pull": "tmem.terms.pull:Pull",\n    "shove": "tmem.terms.shove:Shove",\n'),
    ],
    "key of the law": [
        ("law/params.py", "    energy_tolerance: Annotated[float, Field(gt=0, lt=1)] = 0.05\n",
         "    energy_tolerance: Annotated[float, Field(gt=0, lt=1)] = 0.05\n    attraction_gain: Positive = 1.0\n"),
        ("law/interaction/kernels.py", "    c_max: float\n\n", "    c_max: float\n    attraction_gain: float = 1.0\n\n"),
        ("law/interaction/kernels.py", "    return _saturate(_spring(r, p), p.c_max) if r < p.reach else 0.0\n",
         "    return _saturate(p.attraction_gain * _spring(r, p), p.c_max) if r < p.reach else 0.0\n"),
    ],
}
@pytest.fixture(scope="module")
def extended(tmp_path_factory) -> Path:
    """A copy of the package with every extension applied; its own Numba cache."""
    root = tmp_path_factory.mktemp("extended")
    shutil.copytree(SOURCE, root / "tmem", ignore=shutil.ignore_patterns("__pycache__"))
    for edits in EXTENSIONS.values():
        for name, old, new in edits:
            path = root / "tmem" / name
            if not old:  # a new file
                path.write_text(new)
                continue
            text = path.read_text()
            assert text.count(old) == 1, (name, old)
            path.write_text(text.replace(old, new))
    return root


def run(root: Path, code: str) -> dict:
    """Run ``code`` with the extended copy importable; it prints one JSON object."""
    env = dict(os.environ, PYTHONPATH=str(root), NUMBA_CACHE_DIR=str(root / "numba-cache"))
    done = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], env=env, capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_each_extension_touches_the_files_the_architecture_page_counts():
    page = (SOURCE.parents[1] / "docs" / "architecture.md").read_text()
    for name, edits in EXTENSIONS.items():
        files = sorted({file for file, _, _ in edits})
        assert f"{name}: {len(files)} file" in page, (name, files)
        for file in files:
            assert f"`src/tmem/{file}`" in page, file


def test_a_new_interaction_function_is_chosen_by_name_and_run_by_the_loop(extended):
    """Two agents at rest 30 m apart feel c_max / 2 apart from the new function, in a pair of two and
    among the neighbours of an 80-agent swarm; the schema and evaluate know its name."""
    out = run(extended, '''
        import json
        import tmem
        from tmem.scenario import from_dict
        results = {}
        for n in (2, 80):
            agents = [{"position": 0.0}, {"position": 30.0}] + [{"position": 1000.0 + 100.0 * k} for k in range(n - 2)]
            s = from_dict({"interaction": {"function": "plateau"}, "agents": agents,
                           "simulation": {"dt": 0.01, "duration": 0.1, "record_every": 1}})
            tr = tmem.simulate(s)
            results[n] = [float(tr.control[0, 0, 0]), float(tr.control[0, 1, 0])]
        results["evaluate"] = tmem.law.interaction.evaluate("plateau", [-30.0, 30.0, 45.0], k_p=1.0, reach=40.0, d_t=35.0, c_max=0.1).tolist()
        print(json.dumps(results))
    ''')
    for n in ("2", "80"):
        assert out[n] == pytest.approx([-0.05, 0.05], rel=1e-15)
    assert out["evaluate"] == [0.05, -0.05, 0.0]


def test_a_new_vehicle_model_gets_its_gains_placed_and_flies_its_own_dynamics(extended):
    """The drag model: its gains put the closed loop's roots at (5) (pole placement, since its (A, B)
    is not the paper's), and an agent far from others, level, decays as V0 exp(-c_d t)."""
    out = run(extended, '''
        import json
        import numpy as np
        import tmem
        from tmem.vehicles import vehicle_model
        from tmem.scenario import from_dict
        s = from_dict({"model": {"kind": "drag", "c_d": 0.5}, "interaction": {"function": "repulsion"},
                       "agents": [{"position": 0.0, "velocity": 2.0}, {"position": 5000.0}],
                       "simulation": {"dt": 0.01, "duration": 4.0, "record_every": 10}})
        tr = tmem.simulate(s)
        a, b = vehicle_model(s.model).linearisation()
        roots = np.linalg.eigvals(a - np.outer(b, tr.gains))
        print(json.dumps({"t": tr.time.tolist(), "v": tr.state[:, 0, 0, 1].tolist(), "names": list(tr.model.state_names),
                          "roots": sorted([[r.real, r.imag] for r in roots])}))
    ''')
    t = np.array(out["t"])
    np.testing.assert_allclose(out["v"], 2.0 * np.exp(-0.5 * t), rtol=1e-11)
    expected = sorted([[-12.0, -0.1], [-12.0, 0.1], [0.0, -0.55], [0.0, 0.55]])
    np.testing.assert_allclose(out["roots"], expected, atol=1e-6)
    assert out["names"] == ["P", "V", "phi", "omega"]


def test_a_new_sensing_effect_changes_what_the_agents_know(extended):
    """Neighbours' positions known to the nearest metre: agent 0 at 0 m pushes as if agent 1, at 30.4 m,
    were 30 m away (attraction, unsaturated: K_P (30 - 35)); with a quantum of 1e-9 m the run is the
    exact one to 1e-9."""
    out = run(extended, '''
        import json
        import numpy as np
        import tmem
        from tmem.scenario import from_dict
        s = from_dict({"interaction": {"function": "attraction", "c_max": 1.0},
                       "agents": [{"position": 0.0}, {"position": 30.4}],
                       "simulation": {"dt": 0.01, "duration": 5.0, "record_every": 1}})
        exact = tmem.simulate(s)
        metre = tmem.simulate(s, sensing={"quantum": 1.0})
        fine = tmem.simulate(s, sensing={"quantum": 1e-9})
        print(json.dumps({"k_p": float(exact.gains[0]), "first": float(metre.control[0, 0, 0]),
                          "fine": float(np.abs(fine.state - exact.state).max())}))
    ''')
    k_p = out["k_p"]
    assert out["first"] == pytest.approx(k_p * (30.0 - 35.0), rel=1e-12)
    assert out["fine"] < 1e-6
    assert np.isfinite(out["fine"])


def test_a_new_agent_term_pushes_every_agent_with_no_edit_of_the_engine(extended):
    """The toy term ``[shove]``: a constant push along x on every agent, its own table, record and
    kernel, and a row in the registry.  Two agents far apart, level, pushed by ``level``: each is the
    linear model (2) under a held input, ``x_N = Ad^N x_0 + sum_k Ad^k Bd U``."""
    out = run(extended, '''
        import json
        import tmem
        from tmem.scenario import from_dict
        s = from_dict({"interaction": {"function": "repulsion"}, "shove": {"level": 0.02},
                       "agents": [{"position": 0.0}, {"position": 5000.0}],
                       "simulation": {"dt": 0.01, "duration": 3.0, "record_every": 300}})
        tr = tmem.simulate(s)
        print(json.dumps({"final": tr.final_state[:, 0, :].tolist(), "terms": list(s.agent_terms)}))
    ''')
    from scipy.linalg import expm

    a = np.array([[0, 1, 0, 0], [0, 0, 9.8, 0], [0, 0, 0, 1], [0, 0, -150.0, -25.0]])
    b = np.array([0, 0, 0, 150.0])
    augmented = np.zeros((5, 5))
    augmented[:4, :4], augmented[:4, 4] = a, b
    hold = expm(augmented * 0.01)
    x = np.zeros((2, 4))
    x[1, 0] = 5000.0
    for _ in range(300):
        x = x @ hold[:4, :4].T + 0.02 * hold[:4, 4]
    np.testing.assert_allclose(out["final"], x, rtol=1e-10, atol=1e-12)
    assert out["terms"] == ["shove"]


def test_a_new_key_of_the_law_reaches_the_scenario_the_engine_and_the_per_agent_controller(extended):
    """``interaction.attraction_gain`` scales the attraction (Fig. 3): the push at the first step within
    reach is ``gain K_P (r - d_t)`` (unsaturated), in the engine's record and in a controller's update."""
    out = run(extended, '''
        import json
        import numpy as np
        import tmem
        from tmem.agent import controllers_for
        from tmem.scenario import from_dict
        s = from_dict({"interaction": {"function": "attraction", "c_max": 1.0, "attraction_gain": 2.0},
                       "agents": [{"position": 0.0}, {"position": 30.0}],
                       "simulation": {"dt": 0.01, "duration": 0.1, "record_every": 1}})
        tr = tmem.simulate(s)
        controllers = controllers_for(s)
        state = np.zeros((1, 4))
        messages = [c.message(np.array([[p, 0.0, 0.0, 0.0]]), 0.0) for c, p in zip(controllers, (0.0, 30.0))]
        u = controllers[0].update(state, messages, 0.0)
        print(json.dumps({"k_p": float(tr.gains[0]), "engine": float(tr.control[0, 0, 0]), "agent": float(u[0])}))
    ''')
    expected = 2.0 * out["k_p"] * (30.0 - 35.0)  # agent 0, 5 m inside d_t: pushed away, twice as hard
    assert out["engine"] == pytest.approx(expected, rel=1e-12)
    assert out["agent"] == pytest.approx(expected, rel=1e-12)
