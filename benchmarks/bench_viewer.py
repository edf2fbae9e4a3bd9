"""Size and load time of ``tmem view`` pages: prints figures and, with ``--json``, writes them.

Two runs, simulated first (not timed here):

1. the 19-agent hex, ``examples/swarm/hex19.toml`` as shipped (60 s, 6001 recorded times);
2. a 10 000-agent 3-D gas: ``examples/swarm/gas3d.toml`` with ``swarm.n = 10000`` in a periodic
   cube of 1600 m (the example's density) for 10 s, recorded every 0.1 s; the page thins it to
   1000 agents.

For each: the time ``tmem view`` takes to write the page (median of ``--repeat``), the file's
size, and its load time in headless Chromium (Debian's ``/usr/bin/chromium``): from the start of
navigation to the viewer's first frame drawn with its panels (``tmemViewer.readyMs``), median of
``--repeat`` loads, each in a new page of one browser.

Usage::

    python benchmarks/bench_viewer.py [--repeat 3] [--json benchmarks/results/viewer.json] [--keep DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path

import tmem
from tmem.files.io import write_run
from tmem.scenario import load, with_changes
from tmem.figures.viewer import write_view

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = "/usr/bin/chromium"
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--no-first-run"]  # fmt: skip


def scenarios() -> dict:
    gas = with_changes(
        load(ROOT / "examples" / "swarm" / "gas3d.toml"),
        {"name": "gas-3d-10k", "swarm.n": 10_000, "space.box": [1600.0] * 3, "simulation.duration": 10.0},
    )
    return {"hex19": load(ROOT / "examples" / "swarm" / "hex19.toml"), "gas-3d-10k": gas}


def load_times(browser, page: Path, repeat: int) -> list[float]:
    times = []
    for _ in range(repeat):
        tab = browser.new_page(viewport={"width": 1400, "height": 860})
        errors = []
        tab.on("pageerror", lambda e: errors.append(str(e)))
        tab.goto(page.as_uri())
        tab.wait_for_selector("body[data-ready=true]", timeout=60_000)
        times.append(tab.evaluate("tmemViewer.readyMs") / 1000)
        tab.close()
        if errors:
            raise RuntimeError(f"{page}: {errors}")
    return times


def measure(repeat: int, work: Path) -> dict:
    from playwright.sync_api import sync_playwright

    results = {}
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(executable_path=CHROMIUM, args=FLAGS)
        for name, scenario in scenarios().items():
            started = time.perf_counter()
            trajectory = tmem.simulate(scenario)
            write_run(trajectory, work / name)
            simulated = time.perf_counter() - started
            writes = []
            for _ in range(repeat):
                started = time.perf_counter()
                page = write_view(work / name, work / f"{name}.html")
                writes.append(time.perf_counter() - started)
            loads = load_times(browser, page, repeat)
            results[name] = {
                "agents": int(trajectory.state.shape[1]),
                "recorded_times": len(trajectory.time),
                "simulate_and_write_run_s": simulated,
                "view_write_s": statistics.median(writes),
                "page_bytes": page.stat().st_size,
                "load_s": statistics.median(loads),
                "load_s_all": loads,
            }
            print(f"{name:>11}: {results[name]['agents']} agents, {results[name]['recorded_times']} recorded times; "
                  f"page {page.stat().st_size / 2**20:.2f} MiB written in {results[name]['view_write_s']:.2f} s; "
                  f"opens in {results[name]['load_s']:.2f} s (median of {repeat}: "
                  f"{', '.join(f'{t:.2f}' for t in loads)})", flush=True)  # fmt: skip
        results["chromium"] = browser.version
        browser.close()
    return results


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", type=Path, help="write the figures to this file")
    parser.add_argument("--keep", type=Path, help="keep the runs and pages in this directory (default: a temporary one)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        work = args.keep or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        results = measure(args.repeat, work)
    results["machine"] = {
        "python": platform.python_version(),
        "processor": platform.processor() or platform.machine(),
        "cores": os.cpu_count(),
        "load_average_1min_at_end": os.getloadavg()[0],  # other work on the machine slows the loads
    }
    print(f"load average at the end (1 min): {results['machine']['load_average_1min_at_end']:.1f} on {os.cpu_count()} cores")
    if args.json:
        args.json.write_text(json.dumps(results, indent=1) + "\n")


if __name__ == "__main__":
    main()
