"""What the encounter studies' write-ups share: where they write, and the paper's numbers."""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

from tmem.paper.report import PAPER  # noqa: E402

DOCS = Path(__file__).resolve().parents[1]
FIGURES = DOCS / "encounters"
FUNCTION = "interaction.function"
LABEL = {"switching": "switching (10)", "improved": "improved (11)"}
PAPER_RMS = {"switching": PAPER["fig7"].rms_change_percent, "improved": PAPER["fig9"].rms_change_percent}


def panels_by_function(table, draw, xlabel: str, name: str) -> None:
    """One panel per function, stacked, each drawn by ``draw(ax, function, rows)``; saved as ``FIGURES / name``."""
    import matplotlib.pyplot as plt

    FIGURES.mkdir(exist_ok=True)
    groups = list(table.groupby(FUNCTION, sort=False))
    fig, axes = plt.subplots(len(groups), 1, figsize=(7, 2.8 * len(groups)), squeeze=False)
    for ax, (function, group) in zip(axes[:, 0], groups):
        draw(ax, function, group)
        ax.set_title(LABEL[function], fontsize=10)
        ax.set_ylabel("encounters")
        ax.legend(fontsize=8)
    axes[-1, 0].set_xlabel(xlabel)
    fig.tight_layout()
    fig.savefig(FIGURES / name, dpi=100)
    plt.close(fig)
