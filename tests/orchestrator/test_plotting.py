"""Long curves are drawn from their min/max envelope: fewer points, every extreme kept."""

from __future__ import annotations

import numpy as np
import pytest

from orchestrator.plotting import ENVELOPE_BINS, envelope


def test_the_envelope_of_a_600_s_run_keeps_every_bins_minimum_and_maximum():
    rng = np.random.default_rng(3)
    t = np.arange(120_001) * 5e-3  # 600 s at 5 ms
    y = np.sin(2 * np.pi * 426.7 * t) * 1e5 + rng.normal(0.0, 1e3, t.size)
    y[77_777] = 5e6  # a single-sample spike
    tt, yy = envelope(t, y)
    assert tt.size == 2 * ENVELOPE_BINS + (t.size % ENVELOPE_BINS) and np.all(np.diff(tt) > 0)
    assert yy.max() == y.max() == 5e6 and yy.min() == y.min()
    per = t.size // ENVELOPE_BINS
    bins = y[:per * ENVELOPE_BINS].reshape(ENVELOPE_BINS, per)
    pairs = yy[:2 * ENVELOPE_BINS].reshape(ENVELOPE_BINS, 2)
    np.testing.assert_array_equal(pairs.min(axis=1), bins.min(axis=1))
    np.testing.assert_array_equal(pairs.max(axis=1), bins.max(axis=1))
    # every point drawn is a sample, at its own time
    index = np.searchsorted(t, tt)
    np.testing.assert_array_equal(y[index], yy)


@pytest.mark.parametrize("n", [2, 1000, 2 * ENVELOPE_BINS])
def test_short_curves_are_drawn_sample_by_sample(n):
    t = np.linspace(0.0, 1.0, n)
    y = np.cos(t)
    tt, yy = envelope(t, y)
    assert tt is t and yy is y


def test_matplotlib_is_imported_with_its_classes_and_signatures_whole_and_kwdoc_restored():
    import subprocess
    import sys

    code = ("import inspect\nfrom orchestrator.plotting import import_matplotlib\nimport_matplotlib()\n"
            "import matplotlib.artist as artist\nfrom matplotlib.lines import Line2D\n"
            "assert artist.kwdoc.__module__ == 'matplotlib.artist', artist.kwdoc\n"
            "assert 'color' in inspect.signature(Line2D.set).parameters\n"
            "assert 'linewidth' in artist.kwdoc(Line2D)\n"
            "print('Properties:' in Line2D.set.__doc__, 'Properties:' in artist.Artist.set.__doc__)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    # the tables of the classes the import defines are left empty (the import's cost), matplotlib's base keeps its
    assert proc.stdout.split() == ["False", "True"]
