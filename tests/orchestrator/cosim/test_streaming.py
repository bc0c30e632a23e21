"""The master hands finished blocks of rows to a sink: block size does not change a result, memory stays bounded."""

from __future__ import annotations

import numpy as np
import pytest

from orchestrator.cosim import master
from orchestrator.cosim.master import CoSimulation
from orchestrator.cosim.stop_requests import StopRequests
from orchestrator.cosim.system import resolve_system
from orchestrator.inputs.scenario_file import load_scenario
from tests.orchestrator.cosim.test_master import MASSES


class ListSink:
    """Keeps every chunk it is given (and can fail on a chosen chunk like a full disk)."""

    def __init__(self, fail_at_chunk: int | None = None) -> None:
        self.chunks: list[tuple[np.ndarray, np.ndarray]] = []
        self.fail_at_chunk = fail_at_chunk

    def append(self, time_s, values):
        if self.fail_at_chunk is not None and len(self.chunks) == self.fail_at_chunk:
            raise OSError(28, "No space left on device", "out/timeseries.csv.partial")
        self.chunks.append((np.array(time_s), np.array(values)))

    def rows(self):
        return np.concatenate([t for t, _ in self.chunks]), np.concatenate([v for _, v in self.chunks])


def masses(toy_scenario, algorithm, extrapolation, interval, stop=2.0):
    text = MASSES.format(step=1e-3, algorithm=algorithm).replace(
        "output_interval = 0.02", f'output_interval = {interval}\nextrapolation = "{extrapolation}"').replace(
        "stop = 2.0", f"stop = {stop}")
    return resolve_system(load_scenario(toy_scenario(text)))


@pytest.mark.parametrize("algorithm, extrapolation, interval, step_loop", [
    ("gauss-seidel", "linear", 0.001, "auto"),  # every step sampled: the block buffer itself
    ("jacobi", "hold", 0.003, "auto"),  # a ring buffer and sample rows that straddle blocks
    ("gauss-seidel", "linear", 0.001, "python"),
    ("gauss-seidel", "linear", 0.003, "python"),
    ("jacobi", "linear", 0.4, "python"),  # fewer samples than blocks
])
def test_block_boundaries_do_not_change_the_results(toy_scenario, monkeypatch, algorithm, extrapolation, interval,
                                                    step_loop):
    system = masses(toy_scenario, algorithm, extrapolation, interval, stop=1.2)
    whole = CoSimulation(system, step_loop=step_loop).run(handle_sigint=False)  # 1200 steps, blocks of 250
    monkeypatch.setattr(master, "BLOCK_STEPS", 7)  # blocks that share no boundary with the sampling
    sink = ListSink()
    small = CoSimulation(system, step_loop=step_loop).run(handle_sigint=False, sink=sink)
    assert whole.complete and small.complete and whole.steps == small.steps == 1200
    np.testing.assert_array_equal(small.values, whole.values)
    np.testing.assert_array_equal(small.time_s, whole.time_s)
    t, v = sink.rows()  # the sink saw every row once, in order, the same as the outcome keeps
    np.testing.assert_array_equal(t, whole.time_s)
    np.testing.assert_array_equal(v, whole.values)
    assert whole.time_s.size == 1200 // round(interval / 1e-3) + 1
    assert sink.chunks[0][0].tolist() == [0.0]  # row 0 (the initial state) first, on its own


def test_without_keeping_values_the_outcome_holds_no_rows_and_the_sink_all(toy_scenario):
    system = masses(toy_scenario, "gauss-seidel", "hold", 0.001)
    sink = ListSink()
    out = CoSimulation(system).run(handle_sigint=False, sink=sink, keep_values=False)
    assert out.complete and out.time_s.size == 0 and out.values.shape == (0, 1)
    t, v = sink.rows()
    assert t.size == 2001 and len(sink.chunks) == 1 + 2000 // master.BLOCK_STEPS


def test_a_sink_that_cannot_write_stops_the_run_and_keeps_the_rows_before(toy_scenario):
    system = masses(toy_scenario, "gauss-seidel", "hold", 0.001)
    sink = ListSink(fail_at_chunk=3)  # row 0, two blocks of 250 steps, then the disk is full
    out = CoSimulation(system).run(handle_sigint=False, sink=sink)
    assert not out.complete and out.stage == "writing" and not out.interrupted
    assert out.steps == 750 and out.stopped_at_s == pytest.approx(0.75)
    assert out.error == ("results not written: cannot write out/timeseries.csv.partial: No space left on device "
                         "at t = 0.75 s")
    assert sum(t.size for t, _ in sink.chunks) == 501


def test_a_stop_request_ends_the_run_between_blocks(toy_scenario, monkeypatch):
    system = masses(toy_scenario, "gauss-seidel", "hold", 0.001)
    stop = StopRequests(enabled=False)

    def progress(done, total):
        if done >= 500:
            stop.request(15)  # as if SIGTERM had arrived

    out = CoSimulation(system).run(progress=progress, stop=stop)
    assert not out.complete and out.interrupted and out.stop_signal == "SIGTERM"
    assert out.steps == 500 and out.time_s.size == 501
    assert out.error == "interrupted by SIGTERM at t = 0.5 s"


def test_a_stop_request_before_the_first_step_raises_with_the_stage(toy_scenario):
    from orchestrator.errors import RunInterrupted

    system = masses(toy_scenario, "gauss-seidel", "hold", 0.001)
    stop = StopRequests(enabled=False)
    stop.request(2)
    with pytest.raises(RunInterrupted, match="interrupted by the user \\(Ctrl-C\\) during instantiation") as info:
        CoSimulation(system).run(stop=stop)
    assert info.value.signum == 2
