"""The driver torque figure (pinmech/draw/plot_torque.py): what it draws is the textbook's
energy fluctuation, ΔE = max E − min E with E(θ) = ∫ (T̄ − T) dθ, checked against closed
forms and against an independent trapezoid integration of the hand torque curve."""

from __future__ import annotations

from pathlib import Path

import closed_form_forces as cff
import numpy as np
import pytest

pytest.importorskip("matplotlib", reason='needs pip install "pinmech[plot]"')

import pinmech.draw.plot_torque as plot_torque  # noqa: E402
from pinmech.cli import main  # noqa: E402
from pinmech.draw.plot_torque import torque_curve, torque_figure  # noqa: E402

SCENE = Path(__file__).resolve().parents[1] / "models" / "scenes" / "slider_crank_dynamic.toml"
OMEGA = 3000 * np.pi / 30  # the scene's 3000 rpm [rad/s]


def _drawn(monkeypatch) -> list:
    """Record every torque figure the CLI draws (the figure itself, before it is saved)."""
    figures = []

    def keep(curve, title):
        fig = torque_figure(curve, title)
        figures.append(fig)
        return fig

    monkeypatch.setattr(plot_torque, "torque_figure", keep)
    return figures


def _line(ax, label_start: str):
    return next(line for line in ax.lines if str(line.get_label()).startswith(label_start))


@pytest.mark.parametrize("start_deg", [0.0, 45.0, 200.0])
def test_a_sine_torque_stores_twice_its_amplitude_and_is_drawn_over_0_to_360(start_deg):
    """T = T̄ + A sin θ over one turn: E(θ) = ∫ (T̄ − T) = A (cos θ − cos θ0), so ΔE = 2A,
    E max at θ = 0 (ω max) and E min at 180° (ω min), and T̄ − T = 0 at 0° and 180°.
    3601 poses: the trapezoid error is about h²/12 · A ≈ 2e-7 A; tolerance 1e-6 A. The
    figure is on 0-360° whatever angle the sweep began at."""
    mean, amplitude = 3.0, 40.0
    theta = np.radians(start_deg) + np.linspace(0.0, 2 * np.pi, 3601)
    curve = torque_curve("O", theta, mean + amplitude * np.sin(theta), angular=True, cycle=True)
    assert curve.energy_fluctuation == pytest.approx(2 * amplitude, abs=1e-6 * amplitude)
    assert curve.mean == pytest.approx(mean, abs=1e-6 * amplitude)
    assert (curve.x.min(), curve.x.max()) == (pytest.approx(0.0, abs=1e-9), pytest.approx(360.0))
    np.testing.assert_allclose(curve.energy, amplitude * (np.cos(np.radians(curve.x)) - np.cos(theta[0])),
                               atol=1e-6 * amplitude)
    fig = torque_figure(curve, "sine")
    energy_ax = fig.axes[1]
    top, bottom = _line(energy_ax, "E max"), _line(energy_ax, "E min")
    assert top.get_xdata()[0] % 360.0 == pytest.approx(0.0, abs=0.1) or top.get_xdata()[0] == pytest.approx(360.0)
    assert bottom.get_xdata()[0] == pytest.approx(180.0, abs=0.1)  # one pose is 0.1 deg
    assert top.get_ydata()[0] - bottom.get_ydata()[0] == pytest.approx(2 * amplitude, abs=1e-6 * amplitude)
    assert any(t.get_text() == "ΔE = 80 J" for t in energy_ax.texts)
    assert fig.axes[0].get_ylabel() == "driver torque T [N·m]"
    assert fig.axes[0].get_xlim() == (0.0, 360.0)


def test_the_zeros_of_the_torque_are_marked_where_it_changes_sign():
    """T = 5 sin(2θ) from 10°: zeros at 90°, 180°, 270° and 360° (= 0°); marks within one
    pose's linear interpolation (the error of a chord at a sine's zero is below 1e-6 deg)."""
    theta = np.radians(10.0) + np.linspace(0.0, 2 * np.pi, 721)
    curve = torque_curve("O", theta, 5 * np.sin(2 * theta), angular=True, cycle=True)
    np.testing.assert_allclose(curve.zeros, [0.0, 90.0, 180.0, 270.0], atol=1e-6)
    marks = _line(torque_figure(curve, "zeros").axes[0], "T = 0")
    np.testing.assert_allclose(sorted(marks.get_xdata()), [0.0, 90.0, 180.0, 270.0], atol=1e-6)


def test_the_slider_cranks_energy_panel_is_the_trapezoid_integral_of_the_hand_torque(tmp_path, monkeypatch):
    """The offset slider-crank at 3000 rpm (scene slider_crank_dynamic): the hand torque of
    scripts/closed_form_forces.py (Newton-Euler per link), integrated here by trapezoids,
    gives E(θ) = ∫ (T̄ − T) dθ; the drawn E curve and ΔE agree with it to 1e-6 of ΔE (the two
    torque curves agree to 1e-9 of the pin forces: tests/test_forces_scene.py)."""
    figures = _drawn(monkeypatch)
    assert main(["sweep", str(SCENE), "--steps", "361", "--torque-plot", str(tmp_path / "t.png"),
                 "--csv", str(tmp_path / "t.csv")]) == 0
    theta = np.radians(45.0) + np.linspace(0.0, 2 * np.pi, 361)
    torque = np.array([cff.slider_crank_forces(t, OMEGA, 0.0, 0.05, 0.15, 0.01, *cff.SLIDER_CRANK_BODIES,
                                               gravity=(0.0, -9.81), load_B=(-200.0, 0.0)).T for t in theta])
    work = np.concatenate(([0.0], np.cumsum(0.5 * (torque[1:] + torque[:-1]) * np.diff(theta))))
    energy = work[-1] / (2 * np.pi) * (theta - theta[0]) - work
    delta = energy.max() - energy.min()
    fig = figures[0]
    drawn = _line(fig.axes[1], "E(θ)")
    x = np.asarray(drawn.get_xdata())
    expected = np.interp(x, np.degrees(theta - 2 * np.pi), energy, period=360.0)
    np.testing.assert_allclose(drawn.get_ydata(), expected, atol=1e-6 * delta)
    assert any(t.get_text() == f"ΔE = {delta:.4g} J" for t in fig.axes[1].texts)
    assert (x.min(), x.max()) == (0.0, 360.0)  # the sweep's own axis, not 45-405 deg


def test_statics_draws_the_mechanical_advantage_and_no_energy(tmp_path, monkeypatch):
    """`--static`: the torque holding the gas load and gravity (the hand statics, speed 0),
    and the mechanical advantage |F_gas| / |T| [1/m]; no energy fluctuation anywhere.
    Tolerance 1e-9 relative: the same equations solved two ways."""
    figures = _drawn(monkeypatch)
    assert main(["sweep", str(SCENE), "--steps", "73", "--static", "--torque-plot", str(tmp_path / "t.png"),
                 "--csv", str(tmp_path / "t.csv")]) == 0
    fig = figures[0]
    texts = [t.get_text() for ax in fig.axes for t in ax.texts] + [fig._suptitle.get_text()]
    labels = [str(line.get_label()) for ax in fig.axes for line in ax.lines]
    assert not any("energy" in s.lower() or "ΔE" in s for s in texts + labels)
    ma = _line(fig.axes[1], "mechanical advantage")
    x, y = np.asarray(ma.get_xdata()), np.asarray(ma.get_ydata())
    torque = np.array([cff.slider_crank_forces(t, 0.0, 0.0, 0.05, 0.15, 0.01, *cff.SLIDER_CRANK_BODIES,
                                               gravity=(0.0, -9.81), load_B=(-200.0, 0.0)).T
                       for t in np.radians(x)])
    shown = np.isfinite(y)
    np.testing.assert_allclose(y[shown], 200.0 / np.abs(torque[shown]), rtol=1e-9)
    assert fig.axes[1].get_ylabel() == "mechanical advantage [1/m]"


def test_markers_are_drawn_in_every_panel():
    """Limit, toggle or fold positions given as (driver value, label): one vertical line each
    in every panel, the label written once."""
    theta = np.linspace(0.0, 2 * np.pi, 361)
    curve = torque_curve("O", theta, np.sin(theta) + 1.0, angular=True, cycle=True)
    from dataclasses import replace

    fig = torque_figure(replace(curve, markers=[(30.0, "limit"), (210.0, "limit")]), "markers")
    for ax in fig.axes:
        vertical = [line.get_xdata()[0] for line in ax.lines
                    if len(set(np.atleast_1d(line.get_xdata()))) == 1 and len(line.get_xdata()) == 2]
        assert {30.0, 210.0} <= set(vertical)
    assert [t.get_text() for t in fig.axes[0].texts].count("limit") == 2
