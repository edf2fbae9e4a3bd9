"""The worked extensions of docs/architecture.md, carried out on a copy of the package and run.

Each extension is a list of edits (old text, new text), each naming the file it touches; the test
applies them to a copy
of ``src/tmem``, runs a scenario with the copy in a fresh interpreter, and checks the outcome
against a closed form.  The files touched are counted here and in docs/architecture.md: the test
fails if adding a function, a vehicle model or a sensing effect needs more than the page says.
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
        ("interaction/kernels.py", "def _dispatch_source", textwrap.dedent('''\
            @numba.njit(cache=True, inline="always")
            def plateau(r, f_en, p):
                """A toy function: a constant push of c_max / 2 inside the spheres, 0 outside."""
                return -0.5 * p.c_max if r < p.reach else 0.0


            def _dispatch_source''')),
        ("interaction/registry.py", "\n)  # fmt: skip", textwrap.dedent('''
                InteractionFunction(
                    "plateau", "plateau", "none (a toy)", couples=False, continuous=False,
                    summary="c_max / 2 apart inside the spheres, 0 outside",
                ),
            )  # fmt: skip''')),
    ],
    "vehicle model": [
        ("model/drag.py", "", textwrap.dedent('''\
            """A toy vehicle: the linear model (2) with drag on the velocity, V' = g phi - c_d V."""

            from .base import VehicleModel
            from .linear import STATE_NAMES, HoldStep, state_matrices, step_zero_order_hold, zero_order_hold


            class DragModel(VehicleModel):
                kind = "drag"
                state_names = STATE_NAMES
                state_units = ("m", "m s-1", "rad", "rad s-1")
                long_names = ("position", "velocity", "tilt from the vertical", "tilt rate")
                step = step_zero_order_hold

                def linearisation(self):
                    a, b = state_matrices(self.params.kp, self.params.kd, self.params.g)
                    a[1, 1] = -self.params.c_d
                    return a, b

                def step_params(self, dt):
                    return HoldStep(*zero_order_hold(*self.linearisation(), dt))
            ''')),
        ("model/__init__.py", '    "linear": "tmem.vehicles.linear:LinearModel",\n',
         '    "linear": "tmem.vehicles.linear:LinearModel",\n    "drag": "tmem.vehicles.drag:DragModel",\n'),
        ("scenario/tables.py", "def _linear_unless_named", textwrap.dedent('''\
            class DragModelParams(StrictModel):
                """The linear model with drag: ``[model] kind = "drag"``."""

                kind: Literal["drag"]
                kp: Positive = 6.0
                kd: Positive = 25.0
                g: Positive = 9.8
                c_d: Positive = 0.5


            def _linear_unless_named''')),
        ("scenario/tables.py", "LinearModelParams | QuadrotorModelParams,", "LinearModelParams | QuadrotorModelParams | DragModelParams,"),
    ],
    "sensing effect": [
        ("sensing.py", "    work: np.ndarray\n", "    work: np.ndarray\n    quantum: float = 0.0\n"),
        ("sensing.py", "    return p, v, phi, omega\n", textwrap.indent(textwrap.dedent('''\
            if sensing.quantum > 0.0:  # "quantised": positions known to the nearest multiple of quantum
                p = np.round(p / sensing.quantum) * sensing.quantum
            return p, v, phi, omega
        '''), "    ")),
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
