"""The figures of every run, drawn once in fixed layouts: every text inside the figure, nothing hidden, the data drawn."""

from __future__ import annotations

import numpy as np
import pytest

from components.analysis.load_duration import LoadDurationDistribution
from orchestrator.cosim.outcome import RunOutcome
from orchestrator.cosim.resolved import RecordedVariable
from orchestrator.cosim.roles import ComponentRole, Signal
from orchestrator.frozen_map import FrozenMap
from orchestrator.run import analysis_plots, plots

WINDOW = (5.0, 60.0)
T = np.linspace(0.0, 60.0, 3001)
#: (variable, stage, mesh kind) of the paper's gearbox: 3 sun-planet + 3 ring-planet meshes in two stages, one mesh
MESHES = [(f"stage{s}.F_{k}[{p}]", f"stage{s}", {"sp": "sun_planet", "rp": "ring_planet"}[k])
          for s in (1, 2) for k in ("sp", "rp") for p in (1, 2, 3)] + [("stage3.F_mesh", "stage3", "parallel")]


def _outcome(start_peak: float = 0.0) -> tuple[RunOutcome, ComponentRole]:
    """A paper-like run: contact forces fluctuating by ~1 % about their means, with an optional start-up peak."""
    rng = np.random.default_rng(7)
    wind = 1.6755 + 0.01 * np.sin(0.7 * T) + 0.005 * np.sin(2.3 * T + 1.0)
    columns, values, signals = [], [], []
    for i, (var, stage, mesh) in enumerate(MESHES):
        mean = {"stage1": 9.0e5, "stage2": 1.13e5, "stage3": 3.38e5}[stage]
        force = mean * (wind / 1.6755) * (1.0 + 1e-4 * rng.standard_normal())
        force = force + start_peak * mean * np.exp(-T / 0.3) * np.cos(40.0 * T)
        columns.append(RecordedVariable("gearbox", var, i, "N"))
        values.append(force)
        signals.append(Signal(var, "contact_force", FrozenMap({"stage": stage, "mesh": mesh})))
    columns += [RecordedVariable("wind", "omega", 100, "rad/s"), RecordedVariable("generator", "omega", 101, "rad/s")]
    values += [wind, 100.0 * wind * (1.0 + 1e-3 * np.sin(5.0 * T))]
    outcome = RunOutcome(T, np.column_stack(values), tuple(columns), True, T.size - 1, T[-1])
    return outcome, ComponentRole("gearbox", "gearbox", "record", tuple(signals))


@pytest.fixture
def figures(monkeypatch):
    """The figures the plot functions save, drawn, instead of their files."""
    drawn = []

    def keep(fig, path):
        fig.canvas.draw()
        drawn.append(fig)
        return path

    monkeypatch.setattr(plots, "save_figure", keep)
    monkeypatch.setattr(analysis_plots, "save_figure", keep)
    return drawn


def _ldds() -> list[LoadDurationDistribution]:
    edges = np.linspace(2.478e5, 2.598e5, 65)
    time_s = 55.0 * np.exp(-0.5 * ((np.arange(64) - 32.0) / 12.0) ** 2) / 30.0
    time_s[[3, 40]] = 0.0  # empty bins: no bar
    return [LoadDurationDistribution(f"gearbox.shaft{k}.torque", "N.m", edges / k, time_s, None, 55.0)
            for k in (1, 2, 3)]


def _draw_all(figures, start_peak=0.0):
    outcome, gearbox = _outcome(start_peak)
    plots.plot_rotor_speed(outcome, "wind.omega", WINDOW, "rotor_speed.png")
    plots.plot_generator_speed(outcome, "wind.omega", "generator.omega", 100.0, WINDOW, "generator_speed.png")
    plots.plot_contact_forces(outcome, gearbox, WINDOW, "contact_forces.png")
    analysis_plots.plot_load_duration(_ldds(), "load_duration.png")
    return figures


def _drawn_tick_labels(axis, renderer):
    """Window extents of the tick labels drawn (those at ticks inside the axis' view)."""
    low, high = sorted(axis.get_view_interval())
    return [label.get_window_extent(renderer) for label, at in zip(axis.get_ticklabels(), axis.get_ticklocs())
            if label.get_visible() and label.get_text() and low <= at <= high]


@pytest.mark.parametrize("start_peak", [0.0, 0.2])
def test_every_text_of_the_run_figures_is_inside_the_figure(figures, start_peak):
    for fig in _draw_all(figures, start_peak):
        width, height = fig.canvas.get_width_height()
        renderer = fig.canvas.get_renderer()
        # each axes with its tick labels, axis labels, title and legend (also one beside it), and the figure's title
        boxes = [(ax.get_title(loc="left") or ax.get_title() or ax.get_ylabel(), ax.get_tightbbox(renderer))
                 for ax in fig.axes]
        boxes += [(t.get_text(), t.get_window_extent(renderer)) for t in fig.texts if t.get_text()]
        for name, box in boxes:
            assert -0.5 <= box.x0 and box.x1 <= width + 0.5 and -0.5 <= box.y0 and box.y1 <= height + 0.5, (
                f"{name!r} at {box} outside the {width} x {height} figure")


def test_axis_labels_clear_the_tick_labels_and_legends_beside_the_axes_clear_the_next(figures):
    for fig in _draw_all(figures, 0.2):
        renderer = fig.canvas.get_renderer()
        for ax in fig.axes:
            ylabel = ax.yaxis.label.get_window_extent(renderer)
            ticks = _drawn_tick_labels(ax.yaxis, renderer)
            assert ticks and all(ylabel.x1 <= t.x0 for t in ticks), (ax.get_ylabel(), ylabel, ticks)
            if ax.get_xlabel():
                xlabel = ax.xaxis.label.get_window_extent(renderer)
                ticks = _drawn_tick_labels(ax.xaxis, renderer)
                assert ticks and all(xlabel.y1 <= t.y0 for t in ticks), (ax.get_xlabel(), xlabel, ticks)
            legend = ax.get_legend()
            if legend is not None:
                box = legend.get_window_extent(renderer)
                others = [o.get_window_extent(renderer) for o in fig.axes if o is not ax]
                assert not any(box.overlaps(o) for o in others), (legend, box)


@pytest.mark.parametrize("start_peak", [0.0, 0.2])
def test_every_stage_has_the_whole_run_and_the_window_scaled_to_it(figures, start_peak):
    outcome, gearbox = _outcome(start_peak)
    plots.plot_contact_forces(outcome, gearbox, WINDOW, "contact_forces.png")
    (fig,) = figures
    assert len(fig.axes) == 6
    stage1, zoom = fig.axes[0], fig.axes[1]
    # every sample's extremes are drawn: the envelope of stage 1's first curve spans the data
    first = stage1.get_lines()[0].get_ydata()
    assert first.max() == pytest.approx(outcome.values[:, 0].max() / 1e3)
    assert first.min() == pytest.approx(outcome.values[:, 0].min() / 1e3)
    inside = outcome.values[(T >= WINDOW[0]) & (T <= WINDOW[1]), :6] / 1e3  # stage 1's six meshes
    low, high = zoom.get_ylim()
    pad = 0.08 * (inside.max() - inside.min())
    assert (low, high) == pytest.approx((inside.min() - pad, inside.max() + pad))  # the window's range, padded
    assert zoom.get_xlim() == WINDOW
    if start_peak:
        assert high - low < 0.5 * (first.max() - first.min())  # not squeezed by the start-up peak


@pytest.mark.parametrize("start_peak", [0.0, 5.0])
def test_planet_meshes_with_identical_forces_are_drawn_once(figures, start_peak):
    outcome, gearbox = _outcome(start_peak)
    for i in range(6):  # the planets of one stage carry the same force
        outcome.values[:, i] = outcome.values[:, 3 * (i // 3)]
    plots.plot_contact_forces(outcome, gearbox, WINDOW, "contact_forces.png")
    (fig,) = figures
    labels = [t.get_text() for t in fig.axes[len(fig.axes) // 3 - 1].get_legend().get_texts()]
    assert "stage1.F_sp[1] (sun-planet) = [2], [3]" in labels and "stage1.F_rp[1] (ring-planet) = [2], [3]" in labels


def test_the_load_duration_bars_are_the_time_in_each_non_empty_bin(figures):
    ldds = _ldds()
    analysis_plots.plot_load_duration(ldds, "load_duration.png")
    (fig,) = figures
    for ax, ld in zip(fig.axes, ldds):
        (bars,) = ax.collections
        tops = np.array([path.vertices[1:3, 1].max() for path in bars.get_paths()])
        lefts = np.array([path.vertices[0, 0] for path in bars.get_paths()])
        keep = ld.time_s > 0
        np.testing.assert_allclose(tops, ld.time_s[keep])
        np.testing.assert_allclose(lefts, ld.edges[:-1][keep] * 1e-3)
        low, high = ax.get_ylim()
        assert ax.get_yscale() == "log" and low < tops.min() and tops.max() < high
        assert ax.get_xlabel() == f"{ld.name} [kN m]"
