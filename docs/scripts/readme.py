"""The figure of the README's tour: the distance figure of ``tmem run examples/fig9.toml``.

Runs the shipped Fig. 9 scenario as the README's first tour step does, copies its
``distance.png`` to ``docs/images/fig9-distance.png`` and prints the summary the README
quotes::

    python docs/scripts/readme.py         # about 10 seconds once compiled
"""

from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent.parent
sys.path.insert(0, str(ROOT / "src"))

import tmem  # noqa: E402

FIGURE = ROOT / "docs" / "images" / "fig9-distance.png"


def main() -> None:
    """Run Fig. 9, keep its distance figure, print what the README quotes."""
    trajectory = tmem.simulate(tmem.load(ROOT / "examples" / "fig9.toml"))
    with tempfile.TemporaryDirectory() as tmp:
        summary = tmem.write_run(trajectory, Path(tmp) / "fig9")
        shutil.copyfile(Path(tmp) / "fig9" / "distance.png", FIGURE)
    print(f"couple {summary['couple_time']:.2f} s, uncouple {summary['uncouple_time']:.2f} s, "
          f"RMS change {summary['rms_change_percent']:+.3f} %, min distance {summary['min_distance']:.2f} m")  # fmt: skip
    print(f"written {FIGURE.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
