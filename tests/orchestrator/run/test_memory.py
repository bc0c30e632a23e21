"""release_memory between the phases of a run: figure cycles collected, free heap returned (glibc)."""

from __future__ import annotations

import sys
import weakref

import pytest

from orchestrator.plotting import new_figure
from orchestrator.run import memory
from orchestrator.run.memory import release_memory


def test_a_drawn_figure_is_gone_after_release():
    fig, (ax,) = new_figure()
    ax.plot([0.0, 1.0], [0.0, 1.0])
    fig.canvas.draw()  # the Agg renderer holds the pixels
    gone = weakref.ref(fig)
    del fig, ax
    release_memory()
    assert gone() is None


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="malloc_trim is glibc's")
def test_glibc_malloc_trim_is_found_on_linux():
    trim = memory._malloc_trim()
    assert trim is not None
    assert trim(0) in (0, 1)


@pytest.mark.parametrize("held_bytes, released", [(0, False), (memory.LARGE_RUN_BYTES, False),
                                                  (memory.LARGE_RUN_BYTES + 1, True)])
def test_only_large_runs_pay_for_a_full_collection(held_bytes, released):
    fig, (ax,) = new_figure()
    gone = weakref.ref(fig)
    del fig, ax
    assert memory.release_between_phases(held_bytes) is released
    if released:
        assert gone() is None
