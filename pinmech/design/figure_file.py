"""matplotlib for the design figures (`pip install "pinmech[plot]"`), and writing one."""

from __future__ import annotations

from pathlib import Path

from pinmech.outputs import write_with


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


def save(plt, fig, path: str | Path, *, tight: bool = True) -> Path:
    """Lay the figure out (unless `tight` is False: a figure with a colour bar over several
    axes), write it whole (format from the suffix, 110 dpi; see `write_with`) and close it."""
    if tight:
        fig.tight_layout()
    try:
        write_with(path, lambda temporary: fig.savefig(temporary, dpi=110))
    finally:
        plt.close(fig)
    return Path(path)
