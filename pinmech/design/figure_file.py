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


def number_points(ax, points, color: str = "tab:red") -> None:
    """Number the points (N, 2) [data units] 1, 2, ... beside them, each label set off from
    the points' centre outwards and, where it would sit on a label already placed (poses
    crowded together), further out on a thin leader line; the axes grow to hold them.
    Call it once the axes' limits
    are set (the offsets are in points of the figure as those limits scale it)."""
    import numpy as np

    P = np.asarray(points, dtype=float).reshape(-1, 2)
    box = ax.get_position()
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    per_point = max(abs(x1 - x0) / (ax.figure.get_figwidth() * 72 * box.width),
                    abs(y1 - y0) / (ax.figure.get_figheight() * 72 * box.height))  # data units a typographic point
    centre = P.mean(axis=0)
    placed: list[np.ndarray] = []
    for k, p in enumerate(P, start=1):
        out = p - centre
        length = float(np.hypot(*out))
        out = out / length if length > per_point else np.array([1.0, 1.0]) / np.sqrt(2.0)
        for ring in range(10):  # 8 pt from the point, then 8 pt further a ring; 13 pt apart (two digits: 10 pt)
            where = p + out * (8.0 + 8.0 * ring) * per_point
            if all(np.hypot(*(where - other)) > 13.0 * per_point for other in placed):
                break
        placed.append(where)
        leader = {"arrowstyle": "-", "color": color, "lw": 0.5, "alpha": 0.7} if ring else None
        ax.annotate(str(k), tuple(p), xytext=tuple(where), textcoords="data", fontsize=8, color=color,
                    ha="center", va="center", arrowprops=leader,
                    bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.8})
    low = np.min(placed, axis=0) - 8.0 * per_point  # the axes grown to hold the labels (not over a title)
    high = np.max(placed, axis=0) + 8.0 * per_point
    ax.set_xlim(min(x0, x1, low[0]), max(x0, x1, high[0]))
    ax.set_ylim(min(y0, y1, low[1]), max(y0, y1, high[1]))


def save(plt, fig, path: str | Path, *, tight: bool = True) -> Path:
    """Lay the figure out (unless `tight` is False: a figure with a colour bar over several
    axes), write it whole (format from the suffix, 110 dpi; see `write_with`) and close it."""
    from pinmech.draw.figure_style import FIGURE_RC
    from pinmech.draw.label_place import settle

    if tight:
        fig.tight_layout()
    try:
        with plt.rc_context(FIGURE_RC):
            settle(fig)  # labels placed apart once the layout is final
            write_with(path, lambda temporary: fig.savefig(temporary, dpi=110, bbox_inches="tight", pad_inches=0.08))
    finally:
        plt.close(fig)
    return Path(path)
