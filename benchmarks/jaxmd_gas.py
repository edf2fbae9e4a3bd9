"""Throughput of jax-md on the "gas-N" benchmark case, for comparison with tmem.

What it measures, for each N (each N in its own fresh child process):

* ``agent_steps_per_s``: N * steps / wall seconds of one call of the jitted
  step loop (``jax.lax.fori_loop`` over ``simulate.nve`` steps, the neighbour
  list updated with ``nbrs.update(...)`` inside the loop every step), timed
  with ``block_until_ready`` after a warm-up run on the same shapes; the median
  over ``--repeat`` runs (each from the same initial state) is reported, with
  the min and max.
  The CPU seconds of the process over the same runs (all threads, user +
  system) are recorded too, as ``median_cpu_s``: less sensitive than wall time
  to other work on a shared machine (the 1-minute load average before and
  after each child is recorded for that reason).
* ``compile_s``: wall seconds of ``jax.jit(loop).lower(...).compile()`` for
  the final shapes (the lowering plus the XLA compilation, no execution).
* ``peak_mb``: ``resource.getrusage(RUSAGE_SELF).ru_maxrss`` of the child at
  its end (everything: interpreter, jax, compilation, buffers), and
  ``bytes_per_agent`` = (that peak - the peak just after ``import jax`` and
  ``jax_md``) / N.

The case "gas-N": N agents placed uniformly at random in a 2-D periodic
square box of side L = sqrt(N * pi * r_c**2 / 6), so that the mean number of
neighbours within the cutoff r_c = 40 m is 6; each velocity component normal
with standard deviation 3/sqrt(2) m/s (RMS speed 3 m/s); dt = 0.01 s; 1000
steps; nothing recorded. tmem's own physics (a linear quadrocopter model with
a saturated repulsion) is not reproduced: jax-md runs the same workload shape,
a soft-sphere pair potential (``energy.soft_sphere_neighbor_list`` with
sigma = 40, zero beyond 40 m), ``space.periodic(L)``, a cell-list-built
``partition.neighbor_list`` with a skin (``--skin``, jax-md's
``dr_threshold``; ``capacity_multiplier`` at jax-md's default 1.25), velocity
Verlet (``simulate.nve``), unit masses, all on the CPU (``JAX_PLATFORMS=cpu``
is forced) and in float64 unless ``--float32``. If the neighbour list
overflows (``nbrs.did_buffer_overflow`` after the warm-up run) it is
reallocated with more capacity, the loop recompiled and the warm-up rerun.

Choices (``--format``, ``--skin``): jax-md's ``OrderedSparse`` neighbour
list (a Sparse list that stores each pair once; jax-md's own default for this
energy function) and a skin of 8 m, the fastest measured here at N = 1e4 on
2 CPU cores: Sparse was about 1.6x and Dense about 2-4x slower, and skins of
6 to 16 m about equal, 2 m about 2x and jax-md's default 0.2 m over 10x
slower (the list is then rebuilt every few steps).

Pins (checked on Python 3.11, CPU, Linux x86-64): jax-md 0.2.29 (the newest
on PyPI) with jax 0.10.2 and jaxlib 0.10.2 (what pip resolves for it; jax-md
also pulls in flax, optax, e3nn-jax, jraph, pymatgen and more, about 70
packages). Install them in an environment of their own, not tmem's::

    python3 -m venv /tmp/jaxvenv
    /tmp/jaxvenv/bin/pip install "jax-md==0.2.29" "jax==0.10.2" "jaxlib==0.10.2"

or, with the project's optional extra ``bench`` (the same pins), from the
repository root: ``/tmp/jaxvenv/bin/pip install ".[bench]"``. The script needs
only jax and jax-md, not tmem.

Usage::

    python benchmarks/jaxmd_gas.py --n 1000 10000 100000 --steps 1000 --repeat 3 --json out.json

As a module: ``run_case(n, steps=..., ...)`` runs one case in the calling
process and returns the figures as a dict (peak memory then counts whatever
the caller did before); ``measure(n, ...)`` runs it in a fresh child.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

os.environ["JAX_PLATFORMS"] = "cpu"  # before jax is imported, here or in a child

R_CUT = 40.0  # m
MEAN_NEIGHBOURS = 6.0
RMS_SPEED = 3.0  # m/s
DT = 0.01  # s
DEFAULT_STEPS = 1000
DEFAULT_SEED = 20240611
DEFAULT_SKIN = 8.0  # m, jax-md's dr_threshold; fastest here, see the docstring
FORMATS = ("dense", "sparse", "ordered-sparse")
DEFAULT_FORMAT = "ordered-sparse"  # fastest here, see the docstring


def box_side(n: int) -> float:
    """Side of the periodic box in which n agents have on average 6 neighbours within R_CUT."""
    return math.sqrt(n * math.pi * R_CUT**2 / MEAN_NEIGHBOURS)


def _maxrss_bytes() -> int:
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return rss if sys.platform == "darwin" else rss * 1024  # kB on Linux, bytes on macOS


def run_case(
    n: int,
    steps: int = DEFAULT_STEPS,
    repeat: int = 3,
    seed: int = DEFAULT_SEED,
    fmt: str = DEFAULT_FORMAT,
    skin: float = DEFAULT_SKIN,
    capacity_multiplier: float = 1.25,
    float64: bool = True,
) -> dict:
    """Run gas-N with jax-md in this process and return its figures (see the module docstring)."""
    import jax

    jax.config.update("jax_enable_x64", float64)
    import jax.numpy as jnp
    from jax_md import energy, partition, simulate, space

    baseline = _maxrss_bytes()
    dtype = jnp.float64 if float64 else jnp.float32
    fmt_enum = {
        "dense": partition.Dense,
        "sparse": partition.Sparse,
        "ordered-sparse": partition.OrderedSparse,
    }[fmt]

    side = box_side(n)
    displacement, shift = space.periodic(side)
    neighbor_fn, energy_fn = energy.soft_sphere_neighbor_list(
        displacement,
        side,
        sigma=R_CUT,
        dr_threshold=skin,
        capacity_multiplier=capacity_multiplier,
        format=fmt_enum,
    )
    init_fn, apply_fn = simulate.nve(energy_fn, shift, dt=DT)

    key_r, key_v = jax.random.split(jax.random.PRNGKey(seed))
    position = jax.random.uniform(key_r, (n, 2), dtype=dtype, minval=0.0, maxval=side)
    velocity = jax.random.normal(key_v, (n, 2), dtype=dtype) * (RMS_SPEED / math.sqrt(2.0))

    def loop(state, nbrs):
        def body(_, carry):
            state, nbrs = carry
            state = apply_fn(state, neighbor=nbrs)
            nbrs = nbrs.update(state.position)
            return state, nbrs

        return jax.lax.fori_loop(0, steps, body, (state, nbrs))

    extra_capacity = 0
    reallocations = 0
    while True:
        nbrs0 = neighbor_fn.allocate(position, extra_capacity=extra_capacity)
        state0 = init_fn(key_v, position, kT=0.0, mass=1.0, momenta=velocity, neighbor=nbrs0)
        started = time.perf_counter()
        compiled = jax.jit(loop).lower(state0, nbrs0).compile()
        compile_s = time.perf_counter() - started
        started = time.perf_counter()
        state, nbrs = compiled(state0, nbrs0)  # warm-up on the same shapes
        jax.block_until_ready((state, nbrs))
        warmup_s = time.perf_counter() - started
        if not bool(nbrs.did_buffer_overflow):
            break
        reallocations += 1
        # extra_capacity is per agent (jax-md multiplies it by N for the sparse formats, and adds it to the
        # cell capacity too): grow it by a quarter of the current per-agent width
        per_agent = nbrs0.idx.shape[1] if fmt == "dense" else math.ceil(nbrs0.idx.shape[1] / n)
        extra_capacity += max(1, math.ceil(per_agent / 4))
        if reallocations > 10:
            raise RuntimeError(f"neighbour list still overflows after {reallocations} reallocations")

    times, cpu_times = [], []
    for _ in range(repeat):
        started, cpu_started = time.perf_counter(), time.process_time()
        state, nbrs = compiled(state0, nbrs0)
        jax.block_until_ready((state, nbrs))
        times.append(time.perf_counter() - started)
        cpu_times.append(time.process_time() - cpu_started)
        if bool(nbrs.did_buffer_overflow):  # deterministic: cannot happen after a clean warm-up
            raise RuntimeError("neighbour list overflowed in a timed run")
    if not bool(jnp.all(jnp.isfinite(state.position))):
        raise RuntimeError("non-finite positions at the end of the run")

    median = statistics.median(times)
    peak = _maxrss_bytes()
    return {
        "n": n,
        "steps": steps,
        "repeat": repeat,
        "seed": seed,
        "box_side_m": side,
        "format": fmt,
        "skin_m": skin,
        "capacity_multiplier": capacity_multiplier,
        "dtype": "float64" if float64 else "float32",
        "neighbour_list_shape": list(nbrs0.idx.shape),
        "reallocations": reallocations,
        "compile_s": compile_s,
        "warmup_s": warmup_s,
        "times_s": times,
        "median_s": median,
        "cpu_times_s": cpu_times,  # user + system CPU seconds of the process (all threads)
        "median_cpu_s": statistics.median(cpu_times),
        "agent_steps_per_s": n * steps / median,
        "agent_steps_per_s_min": n * steps / max(times),
        "agent_steps_per_s_max": n * steps / min(times),
        "baseline_mb": baseline / 2**20,
        "peak_mb": peak / 2**20,
        "bytes_per_agent": (peak - baseline) / n,
        "jax": jax.__version__,
        "jax_md": _version("jax-md"),
        "jaxlib": _version("jaxlib"),
    }


def _version(dist: str) -> str:
    from importlib.metadata import version

    return version(dist)


def measure(n: int, timeout: float | None = None, **kwargs) -> dict:
    """Run ``run_case(n, **kwargs)`` in a fresh Python child (same interpreter) and return its dict."""
    env = dict(os.environ, JAX_PLATFORMS="cpu")
    code = (
        "import json, sys; sys.path.insert(0, %r); import jaxmd_gas as m; "
        "print('RESULT ' + json.dumps(m.run_case(%d, **json.loads(sys.argv[1]))))"
    ) % (str(Path(__file__).resolve().parent), n)
    proc = subprocess.run(
        [sys.executable, "-c", code, json.dumps(kwargs)],
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    if proc.returncode != 0:
        raise RuntimeError(f"gas-{n} child failed ({proc.returncode}):\n{proc.stderr[-4000:]}")
    line = next(line for line in proc.stdout.splitlines() if line.startswith("RESULT "))
    return json.loads(line[len("RESULT ") :])


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--n", type=int, nargs="+", default=[1000, 10000, 100000])
    parser.add_argument("--steps", type=int, default=DEFAULT_STEPS)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--seed", type=int, default=DEFAULT_SEED)
    parser.add_argument("--format", choices=FORMATS, default=DEFAULT_FORMAT, help="neighbour-list format")
    parser.add_argument("--skin", type=float, default=DEFAULT_SKIN, help="jax-md dr_threshold, m")
    parser.add_argument("--capacity-multiplier", type=float, default=1.25)
    parser.add_argument("--float32", action="store_true", help="single precision (default: float64)")
    parser.add_argument("--json", type=Path, default=None, help="also write the figures here")
    args = parser.parse_args(argv)

    kwargs = {
        "steps": args.steps,
        "repeat": args.repeat,
        "seed": args.seed,
        "fmt": args.format,
        "skin": args.skin,
        "capacity_multiplier": args.capacity_multiplier,
        "float64": not args.float32,
    }
    machine = {"cpus": os.cpu_count(), "platform": platform.platform(), "python": platform.python_version()}
    print(f"machine: {machine['cpus']} CPUs, {machine['platform']}, Python {machine['python']}")
    print(
        f"jax-md gas-N: {args.steps} steps, dt={DT} s, r_c={R_CUT} m, format={args.format}, "
        f"skin={args.skin} m, {'float32' if args.float32 else 'float64'}, median of {args.repeat}, seed {args.seed}"
    )
    header = (
        f"{'N':>9} {'agent-steps/s':>14} {'median s':>9} {'cpu s':>8} {'compile s':>9} {'peak MB':>8} "
        f"{'B/agent':>8} {'nbr idx':>12} {'load':>5}"
    )
    print(header)
    cases = []
    for n in args.n:
        load_before = os.getloadavg()[0]
        res = measure(n, **kwargs)
        res["loadavg_1min_before"] = load_before  # other work on the machine skews the figures
        res["loadavg_1min_after"] = os.getloadavg()[0]
        cases.append(res)
        shape = "x".join(map(str, res["neighbour_list_shape"]))
        print(
            f"{n:>9} {res['agent_steps_per_s']:>14.4g} {res['median_s']:>9.3f} {res['median_cpu_s']:>8.2f} "
            f"{res['compile_s']:>9.2f} {res['peak_mb']:>8.0f} {res['bytes_per_agent']:>8.0f} {shape:>12} "
            f"{load_before:>5.2f}",
            flush=True,
        )
    if args.json is not None:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        out = {"machine": machine, "settings": {**kwargs, "dt": DT, "r_cut": R_CUT}, "cases": cases}
        args.json.write_text(json.dumps(out, indent=2) + "\n")


if __name__ == "__main__":
    main()
