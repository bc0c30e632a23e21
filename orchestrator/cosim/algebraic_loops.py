"""Algebraic loops solved at each communication point by fixed-point iteration (``algebraic_loops = "iterate"``).

An algebraic loop is a cycle of connections on which every output depends
*directly* on the input before it (:mod:`orchestrator.cosim.graph`): at a
communication point ``t`` the loop's values must satisfy ``u = y(u)`` at once,
which a non-iterative master can only approximate with a value one step old.
FMI 2.0 co-simulation allows a master to set inputs and read outputs again at the
same communication point (after ``fmi2DoStep`` returned, or after initialisation):
an output that depends directly on an input is computed from the input's new
value, without a step. So, after every FMU has stepped to ``t_{k+1}`` (and once
after initialisation, for ``t_0``), :class:`LoopSolver` sweeps each loop's
members in stepping order (a nonlinear Gauss-Seidel iteration)::

    for each member:  u = factor * y_source(t_{k+1}) + offset    (its coupled Real inputs)
                      fmi2SetReal(u); y = fmi2GetReal()          (its outputs at t_{k+1})

until no input moved by more than ``loop_tolerance * max(1, |u|)`` in a sweep;
the converged values are recorded at ``t_{k+1}`` and held over the next step like
any coupled value. The iteration converges where the loop's gain is a contraction
(|gain| < 1 around the loop); otherwise the run stops at that communication
point after ``loop_max_iterations`` sweeps, keeping the samples up to the last
converged point, with a message that names the loop, the time and the last move.
No FMU state is rolled back: the sweeps change only inputs at one instant, which
FMI 2 defines without a step.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from .stepping.plan import StepPlan


class LoopNotConverged(Exception):
    """Internal: the iteration of an algebraic loop did not converge at communication point ``k`` (message in args)."""

    def __init__(self, k: int, message: str) -> None:
        super().__init__(message)
        self.k = k


class LoopSolver:
    """Fixed-point sweeps over the members of each algebraic loop (see the module docstring).

    Parameters
    ----------
    plan : StepPlan
        The run's stepping plan: each member's Real inputs, their feeds and its output columns.
    loops : sequence of sequence of str
        The component names of each loop.
    tolerance : float
        Largest move of an input in the last sweep, relative to ``max(1, |u|)``.
    max_iterations : int
        Sweeps per communication point.
    stop : type
        Exception raised as ``stop(slot, function, status, k)`` on a failing FMI status.
    """

    def __init__(self, plan: StepPlan, loops: Sequence[Sequence[str]], tolerance: float, max_iterations: int,
                 stop: type) -> None:
        self.inputs = plan.input_values
        self.groups = [plan.fmus_of(loop) for loop in loops]
        self.names = [", ".join(n) for n in loops]
        self.tolerance = float(tolerance)
        self.max_iterations = int(max_iterations)
        self.stop = stop

    def solve(self, row: np.ndarray, k: int, t: float) -> None:
        """Iterate every loop at the communication point whose values are ``row`` (a contiguous float64 row).

        Raises
        ------
        LoopNotConverged
            After ``max_iterations`` sweeps without convergence (``k``: the step index whose
            end point did not converge).
        """
        address = row.ctypes.data
        tol, stop, buf = self.tolerance, self.stop, self.inputs
        for g, group in enumerate(self.groups):
            moved = 0.0
            for _ in range(self.max_iterations):
                moved = 0.0
                for m in group:
                    for feed in m.feeds:
                        j = feed.input
                        u = feed.factor * row[feed.column] + feed.offset
                        change = abs(u - buf[j]) / max(1.0, abs(u))
                        if not change <= moved:  # also a NaN, which never converges
                            moved = change if change == change else math.inf
                        buf[j] = u
                    inst = m.instance
                    if m.n_inputs:
                        st = inst.set_real(inst.component, m.input_vr_address, m.n_inputs, m.input_address)
                        if st > 1:
                            raise stop(m.slot, "fmi2SetReal", st, k)
                    if m.n_outputs:
                        st = inst.get_real(inst.component, m.output_vr_address, m.n_outputs,
                                           address + m.output_offset)
                        if st > 1:
                            raise stop(m.slot, "fmi2GetReal", st, k)
                if moved <= tol:
                    break
            else:
                raise LoopNotConverged(k, f"the algebraic loop through {self.names[g]} did not converge at t = "
                                          f"{t:.6g} s: an input still moved by {moved:.3g} (relative) after "
                                          f"{self.max_iterations} sweeps (simulation.loop_max_iterations; the loop's "
                                          f"gain must be below 1 in magnitude for the iteration to converge)")
