"""The stepping plan executed in plain Python: one communication step after the other, FMU by FMU.

For each step ``k`` (from ``t_k = t0 + k H`` to ``t_{k+1}``) and each FMU in the
stepping order, :meth:`PythonLoop.advance`

1. computes every coupled Real input from its :class:`~orchestrator.cosim.stepping.plan.Feed`:
   the source's sample at ``t_{k+1}`` if it already stepped in this step (Gauss-Seidel),
   else at ``t_k``; ``linear`` evaluates the line through that sample and the one before
   at ``t_k + H/2`` (``0.5 y_{k+1} + 0.5 y_k``, or ``1.5 y_k - 0.5 y_{k-1}``); a
   transformed connection applies ``factor * value + offset``;
2. sets them with one ``fmi2SetReal`` (and the typed ones through
   :class:`~orchestrator.cosim.values.TypedPorts`), calls ``fmi2DoStep(t_k, H)``;
3. reads the FMU's coupling outputs (all its recorded Real outputs on sampling steps)
   with one ``fmi2GetReal`` into its columns of the row at ``t_{k+1}``.

Then the algebraic loops are iterated on that row (if any) and, with a ring buffer,
a sampling step's row is copied into the block. The compiled executor
(:mod:`~orchestrator.cosim.stepping.compiled_loop`) does the same arithmetic in the
same order, so both record identical values. A failing status raises
:class:`~orchestrator.cosim.stepping.plan.StepFailed`.
"""

from __future__ import annotations

import time

import numpy as np

from ..algebraic_loops import LoopSolver
from ..values import TextStore
from .plan import VALUE_BYTES, FmuStep, RowBuffers, StepFailed, StepPlan

#: the Real FMI calls of one FMU and step, in the order of a profile's timers
TIMED_FUNCTIONS = ("fmi2SetReal", "fmi2DoStep", "fmi2GetReal")


class PythonLoop:
    """Executes a :class:`StepPlan` block by block (see the module docstring).

    Parameters
    ----------
    plan : StepPlan
    buffers : RowBuffers
    text : TextStore
        String values (used by FMUs with String ports).
    loop_solver : LoopSolver, optional
        Iterates the algebraic loops at every communication point.
    """

    def __init__(self, plan: StepPlan, buffers: RowBuffers, text: TextStore,
                 loop_solver: LoopSolver | None = None) -> None:
        self.plan = plan
        self.buffers = buffers
        self.loop_solver = loop_solver
        #: per FMU: its fmi2SetReal, fmi2DoStep and fmi2GetReal (:data:`TIMED_FUNCTIONS` order)
        self.calls = [(f.instance.set_real, f.instance.do_step, f.instance.get_real) for f in plan.fmus]
        #: per FMU: set its typed inputs ``(k, c)``, read its typed outputs ``(k, c)`` (None: it has none)
        self.typed = []
        gauss_seidel = plan.algorithm == "gauss-seidel"
        for fmu in plan.fmus:
            if fmu.ports is None:
                self.typed.append((None, None))
                continue
            before, after = fmu.ports.bind(buffers.ring, text, plan.stride, gauss_seidel, buffers.direct, StepFailed)
            self.typed.append((before if fmu.ports.inputs else None, after if fmu.ports.outputs else None))

    # ------------------------------------------------------------------ the loop
    def advance(self, k_start: int, k_end: int, t0: float, H: float) -> int:
        """Steps ``k_start <= k < k_end``; returns ``k_end`` (raises StepFailed on a failing status)."""
        buffers, stride, fmus = self.buffers, self.plan.stride, self.plan.fmus
        for k in range(k_start, k_end):
            t = t0 + k * H
            rows = buffers.offsets(k, k_start)
            sampling = (k + 1) % stride == 0
            for fmu in fmus:
                self._step(fmu, k, t, H, rows)
                self._read(fmu, k, fmu.n_outputs if sampling else fmu.n_coupling, rows)
            if self.loop_solver is not None:
                self._solve_loops(k, t + H, rows[0])
            if sampling and not buffers.direct:
                buffers.sample(k, k_start)
        return k_end

    def finish_step(self, k: int, first: int, t0: float, H: float, k_start: int) -> int:
        """Complete step ``k`` after the FMU in slot ``first`` ended the simulation at ``t_{k+1}``.

        That FMU returned ``fmi2Discard`` with ``fmi2Terminated`` from ``fmi2DoStep``: its
        outputs are read, the FMUs after it in the stepping order step as usual, and
        every output is read (the master then samples row ``t_{k+1}``, also off the
        output grid). Returns ``k + 1``.
        """
        t = t0 + k * H
        rows = self.buffers.offsets(k, k_start)
        for fmu in self.plan.fmus[first:]:
            if fmu.slot > first:
                self._step(fmu, k, t, H, rows)
            self._read(fmu, k, fmu.n_outputs, rows)
        if self.loop_solver is not None:
            self._solve_loops(k, t + H, rows[0])
        return k + 1

    # ------------------------------------------------------------------ one FMU
    def _step(self, fmu: FmuStep, k: int, t: float, H: float, rows: tuple[int, int, int, int]) -> None:
        """Set the FMU's inputs (Real, then typed) and step it from ``t_k``."""
        new, now, before, c = rows
        if fmu.feeds:
            self._set_inputs(fmu, new, now, before)
        set_typed = self.typed[fmu.slot][0]
        if set_typed is not None:
            set_typed(k, c)
        set_real, do_step, _ = self.calls[fmu.slot]
        component = fmu.instance.component
        if fmu.n_inputs:
            status = set_real(component, fmu.input_vr_address, fmu.n_inputs, fmu.input_address)
            if status > 1:
                raise StepFailed(fmu.slot, "fmi2SetReal", status, k)
        status = do_step(component, t, H, 1)
        if status > 1:
            raise StepFailed(fmu.slot, "fmi2DoStep", status, k)

    def _set_inputs(self, fmu: FmuStep, new: int, now: int, before: int) -> None:
        """Each coupled Real input from its feed (see the module docstring), into the plan's input buffer."""
        flat, inputs = self.buffers.flat, self.plan.input_values
        linear = self.plan.linear
        for feed in fmu.feeds:
            col = feed.column
            if feed.upstream:
                latest, previous, a = new, now, 0.5
            else:
                latest, previous, a = now, before, 1.5
            if linear:
                value = a * flat[latest + col] + (1.0 - a) * flat[previous + col]
            else:
                value = flat[latest + col]
            if feed.transformed:
                value = feed.factor * value + feed.offset
            inputs[feed.input] = value

    def _read(self, fmu: FmuStep, k: int, n: int, rows: tuple[int, int, int, int]) -> None:
        """The first ``n`` Real outputs of the FMU into the row of ``t_{k+1}`` (and its typed outputs)."""
        if n:
            get_real = self.calls[fmu.slot][2]
            row_address = self.buffers.address + rows[0] * VALUE_BYTES
            status = get_real(fmu.instance.component, fmu.output_vr_address, n, row_address + fmu.output_offset)
            if status > 1:
                raise StepFailed(fmu.slot, "fmi2GetReal", status, k)
        read_typed = self.typed[fmu.slot][1]
        if read_typed is not None:
            read_typed(k, rows[3])

    def _solve_loops(self, k: int, t: float, new: int) -> None:
        n = self.buffers.n_columns
        self.loop_solver.solve(self.buffers.flat[new:new + n], k, t)


class ProfiledLoop(PythonLoop):
    """The Python loop timing each FMU's Real FMI calls (``profile=True``; ~1 us per call).

    Parameters
    ----------
    timers : ndarray, shape (n_fmus, 3)
        Seconds of wall time added per FMU to its ``fmi2SetReal``, ``fmi2DoStep`` and
        ``fmi2GetReal`` columns (:data:`TIMED_FUNCTIONS`).
    """

    def __init__(self, plan: StepPlan, buffers: RowBuffers, text: TextStore, timers: np.ndarray,
                 loop_solver: LoopSolver | None = None) -> None:
        super().__init__(plan, buffers, text, loop_solver)
        self.timers = timers
        self.calls = [tuple(_timed(function, timers[slot], column) for column, function in enumerate(calls))
                      for slot, calls in enumerate(self.calls)]


def _timed(function, timer: np.ndarray, column: int):
    """``function`` that adds its wall time to ``timer[column]``."""
    clock = time.perf_counter

    def timed(*args):
        started = clock()
        try:
            return function(*args)
        finally:
            timer[column] += clock() - started

    return timed
