"""Pin tmem's results to the bit, so that a rewrite of the step loop can be shown to change none.

``pin_results.py OUTDIR`` runs a fixed list of scenarios with whatever
``tmem`` is importable (choose it with ``PYTHONPATH=<tree>/src``) and writes
one ``OUTDIR/<item>.npz`` per item, plus ``OUTDIR/index.json`` (what each
item is, its arrays, how long it took, the versions, the items skipped and
why).  ``pin_results.py --compare OLD NEW`` compares two such directories and
prints, per item, ``identical``, ``max relative difference X`` (naming the
worst array) or ``missing``; it exits with status 1 if an item or array is
missing on either side, or an array differs by more than ``--rtol``
(default 0: bit for bit, NaN equal to NaN).

Only the API likely to outlive a refactor is used: ``tmem.preset``,
``tmem.load`` / ``tmem.loads``, ``tmem.scenario.with_changes``,
``tmem.simulate``, ``tmem.summarize``, ``tmem.run_batch`` and ``tmem.agent.fly`` (in a
tree from before ``summarize`` and ``run_batch`` were top-level names, their modules').
A run's pinned arrays are the trajectory's ``time``, ``state``, ``control``,
``active``, ``flag``, ``pair_distance``, ``interaction_distance``,
``min_distance``, ``min_neighbor_distance``, ``final_state`` and
``final_active`` (each read only if present), its events as
``"time kind agents action"`` strings, and every numeric field of
``summarize()`` (``summary.<dotted path>``; ``None`` kept as NaN, strings
left out).  A batch's pinned arrays are every array of its ``BatchResult``.

The items (the scenario inputs come from this tree's ``examples/`` unless
``--examples`` names another):

* the presets fig5, fig7, fig9, repulsion (default dt);
* every scenario under ``examples/``, ``examples/swarm/`` and ``examples/sensing/``; those under
  ``examples/vehicles/`` (the quadrotor), the pairs at dt = 1 ms, the hexes for their first 10 s;
* examples/fig9.toml (dt = 1 ms, 40 s) and the 19-agent hex (3 s) flown by one controller per
  agent (``tmem.agent.fly``);
* gas-N, 2-D, N = 1000 and 10 000, as benchmarks/bench_gas.py builds it
  (1000 steps, final state); a 3-D periodic gas of 2000 agents, 300 steps;
* formations: the 19-agent hex (jitter 1 m) for 20 s; a 12-agent ring that
  loses an agent; the rhombus of examples/swarm/edges.toml coupled again
  after its release;
* the sweeps: examples/sweeps/encounters.toml (10 000 random starts x 2
  functions) on ``run_batch`` with the cases drawn as ``tmem sweep`` draws
  them, and each case of examples/sweeps/triangle_cmax.toml simulated.

Pinning everything takes 4 to 5 minutes on 2 cores, most of it the
encounter study, plus Numba's compilation on a tree's first run.

Skipped: examples/sweeps/parameters.toml (6000 cases, each its own batch:
about 5 min on 2 cores); attraction swarms of more than 32 agents (a known
bug there is to be fixed).

``--write-digests FILE`` writes, beside the arrays, a SHA-256 digest of each pinned array of the
items computed (:func:`digest`) and the environment that made them (:func:`environment`): the small
JSON file ``tests/pin_digests.json`` that ``tests/test_pins.py`` holds a subset of the items to
(:data:`DIGESTED`).  Made from the current code, and checked against a full pin set made with the
same code::

    PYTHONPATH=src python benchmarks/pin_results.py /tmp/pins/full
    PYTHONPATH=src python benchmarks/pin_results.py /tmp/pins/digested --only $(python benchmarks/pin_results.py --digested) \
        --write-digests tests/pin_digests.json
    python benchmarks/pin_results.py --compare /tmp/pins/full /tmp/pins/digested --only $(python benchmarks/pin_results.py --digested)

Usage::

    PYTHONPATH=src python benchmarks/pin_results.py /tmp/pins/base [--only fig9 gas-1000]
    PYTHONPATH=<new tree>/src python benchmarks/pin_results.py /tmp/pins/new
    python benchmarks/pin_results.py --compare /tmp/pins/base /tmp/pins/new [--rtol 0] [--only ITEM ...]
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import itertools
import json
import os
import platform
import sys
import time
import tomllib
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
PRESETS = ("fig5", "fig7", "fig9", "repulsion")
TRAJECTORY_FIELDS = (
    "time", "state", "control", "active", "flag", "pair_distance", "interaction_distance",
    "min_distance", "min_neighbor_distance", "final_state", "final_active",
)  # fmt: skip
#: R + R_j of the default interaction (R = 20 m), as in benchmarks/bench_gas.py.
REACH = 40.0
GAS_STEPS = 1000
SKIPPED = {
    "sweep-parameters": "examples/sweeps/parameters.toml: 6000 cases, each its own batch (eps and "
    "switch_at drawn per case), about 5 min on 2 cores",
    "attraction swarms > 32 agents": "a known bug there is to be fixed, changing their results",
}


#: The items tests/test_pins.py holds to their digests: about a minute on 2 cores once compiled.
#: The paper's presets, the 19-agent hex for 20 s, gas-1000, a sensed example, a per-agent flight.
DIGESTED = (
    "preset-fig5", "preset-fig7", "preset-fig9", "preset-repulsion", "formation-hex19-20s", "gas-1000",
    "sensing-fig9_noise", "agents-fig9",
)  # fmt: skip


@dataclasses.dataclass(frozen=True)
class Item:
    """One pinned result: its name (the file's stem), what it is, and how to compute its arrays."""

    name: str
    what: str
    compute: Callable[[], dict[str, np.ndarray]]


# --- what is pinned of a run ---------------------------------------------------------------------


def event_text(event) -> str:
    """An event (an object or a dict) as ``"time kind agents action"``, the time in full precision."""
    get = event.get if isinstance(event, dict) else lambda key: getattr(event, key, None)
    agents = tuple(int(a) for a in get("agents") or ())
    return f"{float(get('time'))!r} {get('kind')} {agents} {get('action')}"


def numeric_fields(node, path: str) -> dict[str, np.ndarray]:
    """The numbers in a nested dict / list / dataclass, keyed by dotted path.

    Lists of numbers become one array; ``None`` becomes NaN (an event that
    did not happen); strings are left out.
    """
    if dataclasses.is_dataclass(node) and not isinstance(node, type):
        node = dataclasses.asdict(node)
    if isinstance(node, dict):
        return {k: v for key, value in node.items() for k, v in numeric_fields(value, f"{path}.{key}").items()}
    if isinstance(node, (list, tuple)):
        try:
            return {path: np.array(node, dtype=float)}  # numbers, nested lists of numbers, None as NaN
        except (TypeError, ValueError):
            return {k: v for i, value in enumerate(node) for k, v in numeric_fields(value, f"{path}.{i}").items()}
    if node is None:
        return {path: np.array(np.nan)}
    if isinstance(node, (bool, int, float, np.number, np.bool_)):
        return {path: np.asarray(node)}
    return {}


def run_arrays(scenario) -> dict[str, np.ndarray]:
    """Simulate ``scenario``; the trajectory's pinned arrays, its events and its summary's numbers."""
    import tmem

    trajectory = tmem.simulate(scenario)
    arrays = {name: np.asarray(getattr(trajectory, name)) for name in TRAJECTORY_FIELDS if hasattr(trajectory, name)}
    if hasattr(trajectory, "events"):
        arrays["events"] = np.array([event_text(e) for e in trajectory.events], dtype=str)
    arrays.update(numeric_fields(_api("summarize", "metrics")(trajectory), "summary"))
    return arrays


def _api(name: str, old_module: str):
    """``tmem.<name>``, or, in a tree from before it was a top-level name, ``tmem.<old_module>.<name>``."""
    import importlib

    import tmem

    return getattr(tmem, name) if name in getattr(tmem, "__all__", ()) else getattr(importlib.import_module(f"tmem.{old_module}"), name)


def flight_arrays(scenario) -> dict[str, np.ndarray]:
    """Fly ``scenario`` with one controller per agent (``tmem.agent.fly``): its recorded arrays and events."""
    from tmem.agent import fly

    flight = fly(scenario)
    arrays = {name: np.asarray(getattr(flight, name)) for name in ("time", "state", "control", "flag", "final_state")}
    arrays["events"] = np.array([event_text(e) for e in flight.events], dtype=str)
    return arrays


def batch_arrays(result, prefix: str = "") -> dict[str, np.ndarray]:
    """Every array of a ``BatchResult``."""
    fields = {f.name: getattr(result, f.name) for f in dataclasses.fields(result)}
    return {prefix + name: value.astype(str) if value.dtype == object else value
            for name, value in fields.items() if isinstance(value, np.ndarray)}  # fmt: skip


# --- the scenarios -------------------------------------------------------------------------------


def gas_toml(n: int, axes: int, steps: int, seed: int) -> str:
    """A gas of ``n`` agents with 6 neighbours within ``R + R_j`` on average, as TOML.

    In 2-D exactly benchmarks/bench_gas.py's gas-N: a periodic square box of
    side ``sqrt(N pi (R + R_j)^2 / 6)``, RMS speed 3 m/s, repulsion (8),
    Verlet lists with a 4 m skin, dt = 0.01 s; in 3-D the cube of the same
    density of neighbours.  Recorded at the start and the end only.
    """
    if axes == 2:
        side = float(np.sqrt(n * np.pi * REACH**2 / 6))
    else:
        side = float((n * 4 / 3 * np.pi * REACH**3 / 6) ** (1 / 3))
    name = f"gas-{n}" if axes == 2 else f"gas{axes}d-{n}"
    return f"""
name = "{name}"
[interaction]
function = "repulsion"
[space]
axes = {axes}
periodic = true
box = [{", ".join([repr(side)] * axes)}]
[swarm]
n = {n}
seed = {seed}
speed_rms = 3.0
[neighbors]
method = "verlet"
skin = 4.0
[simulation]
dt = 0.01
duration = {steps * 0.01!r}
record_every = {steps}
"""


def sweep_cases(path: Path) -> tuple[object, list[tuple[dict, list[tuple[int, dict]]]]]:
    """The base scenario and cases of a sweep file, drawn as ``tmem sweep`` draws them.

    Returns ``(base, [(setting, [(case number, random draw), ...]), ...])``:
    one entry per grid point, in case order.  Only what the shipped sweeps
    use is read: ``base``, ``seed``, ``cases``, ``[grid]`` and uniform
    ``[random]`` draws (tmem.sweep.spec: one generator from ``seed``, the
    paths drawn in sorted order, all draws of one path at once).
    """
    import tmem

    spec = tomllib.loads(path.read_text())
    unsupported = set(spec) - {"name", "base", "cases", "seed", "metrics", "batch", "grid", "random"}
    if unsupported or any(set(d) != {"uniform"} for d in spec.get("random", {}).values()):
        raise ValueError(f"{path}: only base, grid and uniform random draws are rebuilt here")
    base = tmem.load(path.parent / spec["base"]) if spec["base"].endswith(".toml") else tmem.preset(spec["base"])
    n = spec.get("cases", 1)
    rng = np.random.default_rng(spec.get("seed", 0))
    columns = {p: rng.uniform(*d["uniform"], size=n).tolist() for p, d in sorted(spec.get("random", {}).items())}
    draws = [{p: values[r] for p, values in columns.items()} for r in range(n)]
    grid = spec.get("grid", {})
    settings = [dict(zip(grid, values)) for values in itertools.product(*grid.values())]
    return base, [(s, [(k * n + r, draw) for r, draw in enumerate(draws)]) for k, s in enumerate(settings)]


def encounter_arrays(path: Path, grid_point: int) -> dict[str, np.ndarray]:
    """One grid point of the encounter study on ``run_batch``: every BatchResult array and the starts."""
    from tmem.scenario import with_changes

    run_batch = _api("run_batch", "batch")
    base, points = sweep_cases(path)
    setting, cases = points[grid_point]
    starts = np.array(
        [[[draw.get(f"agents.{a}.{q}", getattr(base.agents[a], q)) for q in ("position", "velocity")] for a in (0, 1)]
         for _, draw in cases]
    )  # fmt: skip
    result = run_batch(with_changes(base, setting), starts[:, :, 0], starts[:, :, 1])
    return {"case": np.array([c for c, _ in cases]), "positions": starts[:, :, 0], "velocities": starts[:, :, 1],
            **batch_arrays(result)}  # fmt: skip


def items(examples: Path) -> list[Item]:
    """Every pinned item, in a fixed order."""
    import tmem
    from tmem.scenario import with_changes

    def load(relative: str, changes: dict | None = None) -> Callable[[], dict[str, np.ndarray]]:
        if changes is None:
            return lambda: run_arrays(tmem.load(examples / relative))
        return lambda: run_arrays(with_changes(tmem.load(examples / relative), changes))

    found = [Item(f"preset-{p}", f"preset {p}, default dt", lambda p=p: run_arrays(tmem.preset(p))) for p in PRESETS]
    for path in sorted(examples.glob("*.toml")) + sorted(examples.glob("swarm/*.toml")):
        relative = path.relative_to(examples).as_posix()
        found.append(Item(f"example-{path.stem}", f"examples/{relative} as shipped", load(relative)))
    for path in sorted(examples.glob("sensing/*.toml")):
        found.append(Item(f"sensing-{path.stem}", f"examples/sensing/{path.name} as shipped", load(f"sensing/{path.name}")))
    for path in sorted(examples.glob("vehicles/*.toml")):
        changes = {"simulation.duration": 10.0} if path.stem.startswith("hex") else {"simulation.dt": 0.001}
        found.append(Item(f"vehicles-{path.stem}", f"examples/vehicles/{path.name} with {changes}",
                          load(f"vehicles/{path.name}", changes)))
    for name, changes in (("fig9", {"simulation.duration": 40.0, "simulation.dt": 0.001}),
                          ("swarm/hex19", {"simulation.duration": 3.0})):
        found.append(Item(f"agents-{Path(name).name}", f"examples/{name}.toml flown by one controller per agent, {changes}",
                          lambda name=name, changes=changes: flight_arrays(with_changes(tmem.load(examples / f"{name}.toml"), changes))))
    for n in (1000, 10000):
        what = f"gas-{n} of benchmarks/bench_gas.py: 2-D, {GAS_STEPS} steps of 0.01 s, recorded at start and end"
        found.append(Item(f"gas-{n}", what, lambda n=n: run_arrays(tmem.loads(gas_toml(n, 2, GAS_STEPS, seed=1)))))
    found.append(
        Item("gas3d-2000", "3-D periodic gas of 2000 agents, 6 neighbours in reach on average, 300 steps of 0.01 s",
             lambda: run_arrays(tmem.loads(gas_toml(2000, 3, 300, seed=3))))
    )  # fmt: skip
    found += [
        Item("formation-hex19-20s", "examples/swarm/hex19.toml (19-agent hex, jitter 1 m) for 20 s",
             load("swarm/hex19.toml", {"simulation.duration": 20.0})),
        Item("formation-ring12-remove", "ring of 12 (jitter 1 m), agent 5 removed at 8 s, 20 s",
             load("swarm/ring8_loss.toml", {"formation.n": 12, "simulation.duration": 20.0,
                                            "commands": [{"time": 8.0, "action": "remove", "agent": 5}]})),
        Item("formation-rhombus-recouple", "examples/swarm/edges.toml, its released pairs coupled again at 45 s",
             load("swarm/edges.toml", {"commands": [
                 {"time": 30.0, "action": "uncouple", "pairs": [[1, 3], [2, 3]]},
                 {"time": 45.0, "action": "couple", "pairs": [[1, 3], [2, 3]]}]})),
    ]  # fmt: skip
    triangle = examples / "sweeps" / "triangle_cmax.toml"
    base, points = sweep_cases(triangle)
    for setting, cases in points:
        case = cases[0][0]  # no random draws: one case per grid point
        what = f"examples/sweeps/triangle_cmax.toml case {case}: {setting}"
        found.append(Item(f"sweep-triangle_cmax-{case}", what,
                          lambda setting=setting: run_arrays(with_changes(base, setting))))  # fmt: skip
    encounters = examples / "sweeps" / "encounters.toml"
    for k, (setting, cases) in enumerate(sweep_cases(encounters)[1]):
        what = f"examples/sweeps/encounters.toml on run_batch: cases {cases[0][0]}..{cases[-1][0]}, {setting}"
        found.append(Item(f"sweep-encounters-{k}", what, lambda k=k: encounter_arrays(encounters, k)))
    return found


# --- writing and comparing -----------------------------------------------------------------------


def digest(array: np.ndarray) -> str:
    """SHA-256 of an array's dtype, shape and bytes, in hexadecimal: equal digests, equal bits."""
    array = np.ascontiguousarray(array)
    return hashlib.sha256(f"{array.dtype.str} {array.shape} ".encode() + array.tobytes()).hexdigest()


def environment() -> dict[str, str]:
    """What the bits depend on besides the code: Numba, LLVM (llvmlite's and its version), NumPy,
    SciPy (the gains' and the zero-order hold's linear algebra), Python, and the processor (the
    kernels are compiled for it, and the linear algebra picks its routines by it)."""
    import llvmlite
    import llvmlite.binding as llvm
    import numba
    import scipy

    return {
        "numba": numba.__version__, "llvmlite": llvmlite.__version__,
        "llvm": ".".join(map(str, llvm.llvm_version_info)), "numpy": np.__version__, "scipy": scipy.__version__,
        "python": platform.python_version(), "machine": platform.machine(), "cpu": llvm.get_host_cpu_name(),
    }  # fmt: skip


def write_digests(path: Path, found: dict[str, tuple[str, dict[str, np.ndarray]]]) -> None:
    """Write ``{item: (what, arrays)}`` as their digests, with the environment, to ``path`` (JSON)."""
    text = {
        "about": "Regression pins: SHA-256 digests of the arrays benchmarks/pin_results.py pins, made by "
        "`pin_results.py OUTDIR --only ... --write-digests` from the code of the commit that wrote this file; "
        "tests/test_pins.py recomputes them and compares",
        "environment": environment(),
        "items": {name: {"what": what, "arrays": {key: digest(a) for key, a in sorted(arrays.items())}}
                  for name, (what, arrays) in found.items()},
    }  # fmt: skip
    path.write_text(json.dumps(text, indent=1) + "\n")
    print(f"digests of {len(found)} items written to {path}")


def pin(out: Path, examples: Path, only: list[str] | None, digests: Path | None = None) -> None:
    """Compute the items (those named in ``only``, or all) and write them with the index to ``out``;
    their digests to ``digests`` if given (:func:`write_digests`)."""
    import numba
    import tmem

    todo = [item for item in items(examples) if not only or item.name in only]
    if only and len(todo) != len(only):
        sys.exit(f"unknown items: {sorted(set(only) - {item.name for item in todo})}")
    out.mkdir(parents=True, exist_ok=True)
    index = {
        "tmem": {"version": getattr(tmem, "__version__", None), "file": tmem.__file__},
        "machine": {"cpus": os.cpu_count(), "numba_threads": numba.get_num_threads(), "platform": platform.platform()},
        "versions": {"python": platform.python_version(), "numpy": np.__version__, "numba": numba.__version__},
        "examples": str(examples),
        "items": {},
        "skipped": SKIPPED,
    }
    total = time.perf_counter()
    found = {}
    for item in todo:
        started = time.perf_counter()
        arrays = item.compute()
        seconds = time.perf_counter() - started
        np.savez(out / f"{item.name}.npz", **arrays)
        if digests is not None:
            with np.load(out / f"{item.name}.npz") as saved:  # what --compare reads: the digests of the file's arrays
                found[item.name] = (item.what, dict(saved))
        index["items"][item.name] = {
            "what": item.what,
            "seconds": round(seconds, 3),
            "arrays": {name: [list(a.shape), a.dtype.str] for name, a in arrays.items()},
        }
        print(f"{item.name:32} {seconds:7.2f} s  {len(arrays)} arrays", flush=True)
    index["seconds"] = round(time.perf_counter() - total, 3)
    (out / "index.json").write_text(json.dumps(index, indent=1) + "\n")
    print(f"{len(todo)} items in {index['seconds']:.1f} s, written to {out}")
    if digests is not None:
        write_digests(digests, found)


def relative_difference(old: np.ndarray, new: np.ndarray) -> float:
    """Largest ``|new - old| / max(|old|, |new|)`` (0 where both are equal, NaN included; inf if only one is NaN)."""
    if old.shape != new.shape:
        return np.inf
    if old.dtype.kind in "USO" or new.dtype.kind in "USO":
        return 0.0 if np.array_equal(old, new) else np.inf
    a, b = old.astype(float), new.astype(float)
    same = (a == b) | (np.isnan(a) & np.isnan(b))
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = np.abs(b - a) / np.maximum(np.abs(a), np.abs(b))
    rel = np.where(same, 0.0, np.where(np.isnan(rel), np.inf, rel))
    return float(rel.max()) if rel.size else 0.0


def identical(old: np.ndarray, new: np.ndarray) -> bool:
    """Same dtype, shape and bits (NaN equal to NaN)."""
    return old.dtype == new.dtype and old.shape == new.shape and old.tobytes() == new.tobytes()


def compare(old: Path, new: Path, rtol: float, only: list[str] | None = None) -> bool:
    """Print one line per item (those named in ``only``, or all) and one per differing array; return
    whether all match within ``rtol``."""
    names = [json.loads((d / "index.json").read_text())["items"] for d in (old, new)]
    ok = True
    for name in sorted(set(only) if only else set(names[0]) | set(names[1])):
        if name not in names[0] or name not in names[1]:
            print(f"{name:32} missing in {old if name not in names[0] else new}")
            ok = False
            continue
        with np.load(old / f"{name}.npz") as a, np.load(new / f"{name}.npz") as b:
            a, b = dict(a), dict(b)
        details, worst, worst_array = [], 0.0, ""
        added = sorted(key for key in set(b) - set(a) if key.startswith("summary."))  # a figure the summary gained
        for key in sorted((set(a) | set(b)) - set(added)):
            if key not in a or key not in b:
                details.append(f"    {key}: missing in {old if key not in a else new}")
                worst, worst_array = np.inf, key
            elif not identical(a[key], b[key]):
                diff = relative_difference(a[key], b[key])
                shapes = f" (shape {a[key].shape} -> {b[key].shape})" if a[key].shape != b[key].shape else ""
                dtypes = f" (dtype {a[key].dtype} -> {b[key].dtype})" if a[key].dtype != b[key].dtype else ""
                details.append(f"    {key}: max relative difference {diff:.3g}{shapes}{dtypes}")
                if diff >= worst:
                    worst, worst_array = diff, key
        if not details:
            print(f"{name:32} identical" + (f" (and the summary's new {', '.join(added)})" if added else ""))
            continue
        print(f"{name:32} max relative difference {worst:.3g} ({worst_array})")
        print("\n".join(details))
        ok = ok and 0 < rtol and worst <= rtol  # with rtol = 0, only identical bits pass
    return ok


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", nargs="?", type=Path, help="directory to write the pinned results to")
    parser.add_argument("--compare", nargs=2, type=Path, metavar=("OLD", "NEW"), help="compare two result directories")
    parser.add_argument("--rtol", type=float, default=0.0, help="largest relative difference accepted (default 0)")
    parser.add_argument("--examples", type=Path, default=ROOT / "examples", help="where the example scenarios are")
    parser.add_argument("--only", nargs="+", metavar="ITEM", help="pin (or compare) only these items")
    parser.add_argument("--write-digests", type=Path, metavar="FILE",
                        help="also write the SHA-256 digests of the items' arrays to FILE (tests/pin_digests.json)")
    parser.add_argument("--digested", action="store_true", help="print the items tests/test_pins.py holds, and exit")
    args = parser.parse_args()
    if args.digested:
        print(" ".join(DIGESTED))
        return
    if args.compare:
        sys.exit(0 if compare(*args.compare, args.rtol, args.only) else 1)
    if args.out is None:
        parser.error("give OUTDIR, or --compare OLD NEW")
    pin(args.out, args.examples.resolve(), args.only, args.write_digests)


if __name__ == "__main__":
    main()
