"""matplotlib for the design figures (`pip install "pinmech[plot]"`), and writing one."""

from __future__ import annotations

from pathlib import Path


def pyplot(what: str):
    """matplotlib.pyplot on the Agg backend; ImportError naming the extra if missing
    (what: the figures asked, e.g. "study")."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise ImportError(f'{what} figures need matplotlib: pip install "pinmech[plot]" ({exc})') from exc
    return plt


def save(plt, fig, path: str | Path) -> Path:
    """Lay the figure out, write it (format from the suffix, 110 dpi) and close it."""
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
