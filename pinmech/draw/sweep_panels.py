"""How a sweep figure draws its panels: one quantity against the driver, a curve per name
in its link's colour (one line style a branch), constants said in the legend, and the
figure's title and the scene's pose as numbers. `SweepPlot` records; this draws."""

from __future__ import annotations

from array import array

import numpy as np

from pinmech.draw.plot_curves import BRANCH_STYLES, angles as _angles, branch_pieces, legend_beside
from pinmech.draw.plot_curves import nearest as _nearest, spike_limits
from pinmech.solve.certify import dial_caption


#: A speed's or acceleration's panel switches from mm to m where its largest value would
#: reach this many mm/s or mm/s² (five digits: 9,999 mm/s² is drawn, 10,000 is 10 m/s²).
RATE_LIMIT = 1e4


class SweepPanels:
    """The panel drawing of `SweepPlot` (its recorded `series`, `branch`, `colours`, `names`,
    `length`, `angles`, `mark` and `sweep`)."""

    def _panel(self, ax, title: str, series: dict[str, array], x: np.ndarray, order: np.ndarray,
               mark_x: float | None) -> None:
        """One quantity against the driver: a curve per name in its link's colour (one line
        style a branch), constant ones said in the legend, a fold's spike clipped."""
        quantity, label = title.split(", ")
        symbol, dim = label.split(" [")
        scale, dim = self._length_dim(dim.rstrip("]"))
        label, dim = f"{symbol} [{dim}]", dim + "]"
        angle = title.startswith("angle")
        curves = {name: _angles(np.array(v)[order], self.angles) if angle else scale * np.array(v)[order]
                  for name, v in series.items()}
        largest = max((float(np.nanmax(np.abs(y))) for y in curves.values() if np.any(np.isfinite(y))), default=0.0)
        flat = max(1e-9 * largest, 1e-12)  # changes below this are rounding (1e-12: noise about an exact 0)
        constants, drawn, branch = [], [], np.array(self.branch)[order]
        is_flat = {name: bool(y[np.isfinite(y)].size) and np.ptp(y[np.isfinite(y)]) <= flat for name, y in curves.items()}
        every_flat = all(is_flat.values())  # an empty panel says less than its flat lines
        for name, y in curves.items():
            if is_flat[name]:
                value = y[np.isfinite(y)][0]
                constants.append(f"{self.names.get(name, name)}: {symbol} = {value:.6g} {dim.rstrip(']')} "
                                 + ("(constant)" if every_flat else "(constant, not drawn)"))
                if not every_flat:
                    continue
            drawn.append(y)
            self._curve(ax, name, x, y, branch)
            if mark_x is not None:
                at = _nearest(x, y, mark_x, scale * self.mark[1][title][name])
                ax.plot([mark_x], [at], "o", color=self.colours.get(name, "k"), markersize=5)
        for text in constants:  # in the legend, not in a box over the curves
            ax.plot([], [], " ", label=text)
        clipped = spike_limits(drawn)
        if clipped is not None:
            ax.set_ylim(clipped[0], clipped[1])
            quantity += f" (clipped: reaches {clipped[2]:.3g} at a fold)"
        if mark_x is not None:
            ax.axvline(mark_x, color="0.35", linestyle="--", linewidth=1)
        name = self.names.get(next(iter(series)), next(iter(series)))
        ax.set_title(f"{name}: {quantity}" if len(series) == 1 else quantity, fontsize=10)
        ax.set_ylabel(label + (f", {self.angles}" if angle else ""))
        ax.grid(True, alpha=0.35)
        legend_beside(ax)

    def _length_dim(self, dim: str) -> tuple[float, str]:
        """(factor, unit) a quantity in SI `dim` is drawn in: the figure's length unit for
        lengths, and for speeds and accelerations too unless the largest of that kind in the
        figure (every panel in `dim`) would reach 10,000 in it: then m/s or m/s², one unit a
        kind in the figure (never 150,000 mm/s²)."""
        if dim not in ("m", "m/s", "m/s²"):
            return 1.0, dim
        scale, unit = self.length
        if dim != "m" and scale != 1.0 and scale * self._largest(dim) >= RATE_LIMIT:
            return 1.0, dim
        return scale, unit + dim[1:]

    def _largest(self, dim: str) -> float:
        """The largest |value| [SI] of the figure's panels in `dim`."""
        out = 0.0
        for title, series in self.series.items():
            if title.endswith(f"[{dim}]"):
                for values in series.values():
                    y = np.abs(np.asarray(values, float))
                    if np.any(np.isfinite(y)):
                        out = max(out, float(np.nanmax(y)))
        return out

    def _curve(self, ax, name: str, x: np.ndarray, y: np.ndarray, branch: np.ndarray) -> None:
        """One name's curve, in its link's colour (a point's in its own colour, with its own
        marker every so often), one line style for each branch."""
        colour = self.colours.get(name, "k")
        marker = getattr(self, "point_markers", {}).get(name)
        extra = {"marker": marker, "markevery": max(1, len(x) // 9), "markersize": 5} if marker else {}
        for b, mask in branch_pieces(branch):
            label = self.names.get(name, name) + (f", assembly {b + 1}" if self._folded else "")
            ax.plot(x, np.where(mask, y, np.nan), linewidth=1.6, color=colour,
                    linestyle=BRANCH_STYLES[b % len(BRANCH_STYLES)], label=label, **extra)

    def _title(self, marked: bool, mark_x: float, unit: str) -> str:
        sweep = self.sweep
        spec = sweep.scene.file.drivers.get(sweep.driver)
        rate = "speed" if sweep.is_angular else "velocity"
        speed = spec.rate if spec is not None and spec.rate is not None else "0"  # as the scene writes it; absent: 0
        acceleration = spec.acceleration if spec is not None and spec.acceleration is not None else "0"
        note = f"dashed: the scene's pose, {mark_x:.4g} {unit}" if marked else ""
        if self.failed:
            note += ("; " if note else "") + f"{len(self.failed)} pose(s) failed (red x)"
        dial = dial_caption(sweep.solver.certify)
        driven = f"driver {sweep.driver} at {rate} {speed}, acceleration {acceleration}"
        return f"{sweep.scene.title}: {driven}" + (f"\n({note})" if note else "") + (f"\n{dial}" if dial else "")

    def _summary(self, mark_x: float, unit: str) -> str:
        lines = [f"At the scene's pose, {self.sweep.driver} = {mark_x:.4g} {unit}:", ""]
        for title, values in self.mark[1].items():
            symbol, dim = title.split(", ")[1].split(" [")
            scale, dim = self._length_dim(dim.rstrip("]"))
            for name, value in values.items():
                lines.append(f"  {self.names.get(name, name) + ' ' + symbol:<18} {scale * value: .5g} {dim}")
        return "\n".join(lines)
