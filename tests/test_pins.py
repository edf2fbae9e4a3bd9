"""Regression pins: a subset of benchmarks/pin_results.py's items, held to the bits they had.

This is the one place where the expected output is tmem's own: ``tests/pin_digests.json`` holds a
SHA-256 digest of every pinned array of each item (the trajectory's states, set-points, flags,
distances and events, every number of its summary), written by ``pin_results.py --write-digests``
from the code of the commit that wrote it.  A digest that changes says that a change to the code
changed a result's bits; whether that is right is for the change to show (``pin_results.py
--compare`` against a pin set of the earlier code says by how much), and the file is then written
again.  The physics is tested elsewhere, against independent references.

Bits depend on more than the code: on Numba, LLVM, NumPy and SciPy, and on the processor the
kernels are compiled for.  Where any of them differs from what the file records, the pins are
skipped with a line that says which.
"""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DIGESTS = json.loads((Path(__file__).parent / "pin_digests.json").read_text())


def _pin_results():
    """benchmarks/pin_results.py as a module."""
    spec = importlib.util.spec_from_file_location("pin_results", ROOT / "benchmarks" / "pin_results.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules.setdefault("pin_results", module)  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


pins = _pin_results()
_here = pins.environment()
_differs = [f"{key} {DIGESTS['environment'].get(key)} -> {_here[key]}" for key in _here if DIGESTS["environment"].get(key) != _here[key]]
if _differs:
    pytest.skip(f"pins recorded in another environment ({', '.join(_differs)}): the bits may differ", allow_module_level=True)


@pytest.fixture(scope="module")
def items():
    return {item.name: item for item in pins.items(ROOT / "examples")}


def test_the_digested_items_are_the_ones_pin_results_names():
    assert sorted(DIGESTS["items"]) == sorted(pins.DIGESTED)


@pytest.mark.parametrize("name", sorted(DIGESTS["items"]))
def test_the_items_keep_their_bits(name, items):
    pinned = DIGESTS["items"][name]
    item = items[name]
    assert item.what == pinned["what"], "the item is no longer what was pinned: write the digests again"
    arrays = item.compute()
    gone = sorted(set(pinned["arrays"]) - set(arrays))
    added = sorted(set(arrays) - set(pinned["arrays"]))
    assert not gone, f"{name}: pinned arrays gone: {', '.join(gone)}"
    # A figure the summary gained is not a difference (as pin_results.py --compare reads it); any other array is.
    assert all(key.startswith("summary.") for key in added), f"{name}: arrays added: {', '.join(added)}"
    changed = [f"{key} {arrays[key].dtype}{arrays[key].shape}" for key in sorted(pinned["arrays"])
               if pins.digest(arrays[key]) != pinned["arrays"][key]]  # fmt: skip
    assert not changed, f"{name}: bits changed in {', '.join(changed)} (see benchmarks/pin_results.py --compare)"
