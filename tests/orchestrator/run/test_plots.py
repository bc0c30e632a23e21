"""The figures of every run, laid out once: every text inside the figure and clear of the others, nothing hidden, the data drawn."""

from __future__ import annotations

import itertools
import subprocess
import sys
from pathlib import Path

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
    """The figures the plot functions save, laid out, instead of their files."""
    laid_out = []

    def keep(fig, path):
        fig.lay_out()
        laid_out.append(fig)
        return path

    monkeypatch.setattr(plots, "save_figure", keep)
    monkeypatch.setattr(analysis_plots, "save_raster_figure", keep)
    return laid_out


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


def _overlap(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


@pytest.mark.parametrize("start_peak", [0.0, 0.2])
def test_every_text_of_the_run_figures_is_inside_the_figure_and_clear_of_the_others(figures, start_peak):
    for fig in _draw_all(figures, start_peak):
        width, height = fig.size
        texts = fig.texts()
        boxes = [(t.text, t.box) for t in texts] + [("legend", ax.legend.box) for ax in fig.flat() if ax.legend]
        for name, (x0, y0, x1, y1) in boxes:
            assert -0.5 <= x0 and x1 <= width + 0.5 and -0.5 <= y0 and y1 <= height + 0.5, (
                f"{name!r} at {(x0, y0, x1, y1)} outside the {width} x {height} figure")
        for a, b in itertools.combinations(texts, 2):
            assert not _overlap(a.box, b.box), (a.text, a.box, b.text, b.box)


def test_axis_labels_clear_the_tick_labels_and_legends_beside_the_axes_clear_the_next(figures):
    for fig in _draw_all(figures, 0.2):
        for ax in fig.flat():
            texts = {role: [t.box for t in ax.texts if t.role == role] for role in ("xtick", "ytick", "xlabel", "ylabel")}
            (ylabel,) = texts["ylabel"]
            assert texts["ytick"] and all(ylabel[2] <= t[0] for t in texts["ytick"]), (ax.ylabel, ylabel)
            if ax.xlabel:
                (xlabel,) = texts["xlabel"]
                assert texts["xtick"] and all(xlabel[1] >= t[3] for t in texts["xtick"]), (ax.xlabel, xlabel)
            if ax.legend is not None:
                assert not any(_overlap(ax.legend.box, other.box) for other in fig.flat() if other is not ax)


@pytest.mark.parametrize("start_peak", [0.0, 0.2])
def test_every_stage_has_the_whole_run_and_the_window_scaled_to_it(figures, start_peak):
    outcome, gearbox = _outcome(start_peak)
    plots.plot_contact_forces(outcome, gearbox, WINDOW, "contact_forces.png")
    (fig,) = figures
    assert (fig.rows, fig.columns) == (3, 2)
    stage1, zoom = fig.axes[0]
    # every sample's extremes are drawn: the envelope of stage 1's first curve spans the data
    first = stage1.lines[0].y
    assert first.max() == pytest.approx(outcome.values[:, 0].max() / 1e3)
    assert first.min() == pytest.approx(outcome.values[:, 0].min() / 1e3)
    inside = outcome.values[(T >= WINDOW[0]) & (T <= WINDOW[1]), :6] / 1e3  # stage 1's six meshes
    low, high = zoom.ylim
    pad = 0.08 * (inside.max() - inside.min())
    assert (low, high) == pytest.approx((inside.min() - pad, inside.max() + pad))  # the window's range, padded
    assert zoom.xlim == WINDOW
    assert [t.value for t in zoom.xticks] == [10.0, 20.0, 30.0, 40.0, 50.0, 60.0]
    if start_peak:
        assert high - low < 0.5 * (first.max() - first.min())  # not squeezed by the start-up peak


@pytest.mark.parametrize("start_peak", [0.0, 5.0])
def test_planet_meshes_with_identical_forces_are_drawn_once(figures, start_peak):
    outcome, gearbox = _outcome(start_peak)
    for i in range(6):  # the planets of one stage carry the same force
        outcome.values[:, i] = outcome.values[:, 3 * (i // 3)]
    plots.plot_contact_forces(outcome, gearbox, WINDOW, "contact_forces.png")
    (fig,) = figures
    zoom = fig.axes[0][1]
    labels = [e.label for e in zoom.legend.entries]
    assert labels == ["stage1.F_sp[1] (sun-planet) = [2], [3]", "stage1.F_rp[1] (ring-planet) = [2], [3]"]
    assert [line.dashed for line in zoom.lines] == [False, True]
    assert "drawn once, named '= [2], [3]'" in fig.suptitle.text


def test_the_load_duration_bars_are_the_time_in_each_non_empty_bin(figures):
    ldds = _ldds()
    analysis_plots.plot_load_duration(ldds, "load_duration.png")
    (fig,) = figures
    for (ax,), ld in zip(fig.axes, ldds):
        (bars,) = ax.bars
        keep = ld.time_s > 0
        np.testing.assert_allclose(bars.top, ld.time_s[keep])
        np.testing.assert_allclose(bars.left, ld.edges[:-1][keep] * 1e-3)
        np.testing.assert_allclose(bars.right, ld.edges[1:][keep] * 1e-3)
        low, high = ax.ylim
        assert ax.yscale == "log" and low < bars.top.min() and bars.top.max() < high
        assert [t.label for t in ax.yticks if t.major] == ["0.01", "0.1", "1"]
        assert ax.xlabel == f"{ld.name} [kN m]"


def test_the_run_figures_are_palette_pngs_drawn_without_matplotlib(tmp_path):
    """The four figures in a fresh process: written as 8-bit palette PNGs at 110 dpi, matplotlib never imported."""
    code = (f"import sys\nsys.path.insert(0, {str(Path(__file__).parent)!r})\nfrom pathlib import Path\n"
            "import test_plots as t\nfrom orchestrator.run import analysis_plots, plots\n"
            f"out = Path({str(tmp_path)!r})\noutcome, gearbox = t._outcome(0.2)\n"
            "plots.plot_rotor_speed(outcome, 'wind.omega', t.WINDOW, out / 'rotor_speed.png')\n"
            "plots.plot_generator_speed(outcome, 'wind.omega', 'generator.omega', 100.0, t.WINDOW,"
            " out / 'generator_speed.png')\n"
            "plots.plot_contact_forces(outcome, gearbox, t.WINDOW, out / 'contact_forces.png')\n"
            "analysis_plots.plot_load_duration(t._ldds(), out / 'load_duration.png')\n"
            "print('matplotlib' in sys.modules)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["False"]
    from PIL import Image

    sizes = {"rotor_speed": (1100, 440), "generator_speed": (1100, 660), "contact_forces": (1650, 968),
             "load_duration": (1100, 847)}
    for name, size in sizes.items():
        with Image.open(tmp_path / f"{name}.png") as image:
            assert (image.mode, image.size) == ("P", size)
            assert image.info["dpi"] == pytest.approx((110, 110), abs=0.01)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(f"{n}.png" for n in sizes)  # no temporary left
