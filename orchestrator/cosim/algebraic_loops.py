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
from typing import Any, Sequence

import numpy as np


class LoopNotConverged(Exception):
    """Internal: the iteration of an algebraic loop did not converge at communication point ``k`` (message in args)."""

    def __init__(self, k: int, message: str) -> None:
        super().__init__(message)
        self.k = k


class _Member:
    """One FMU of a loop: its Real input buffer, the feeds of those inputs and where its outputs go in a row."""

    __slots__ = ("slot", "inst", "buf", "buf_addr", "vr_in", "n_in", "vr_out", "n_out", "out_offset_bytes", "feeds")

    def __init__(self, slot: int, inst: Any, buf, buf_addr: int, vr_in: int, n_in: int, vr_out: int, n_out: int,
                 out_offset_bytes: int, feeds: list[tuple[int, int, float, float]]) -> None:
        self.slot, self.inst, self.buf, self.buf_addr, self.vr_in, self.n_in = slot, inst, buf, buf_addr, vr_in, n_in
        self.vr_out, self.n_out, self.out_offset_bytes, self.feeds = vr_out, n_out, out_offset_bytes, feeds


class LoopSolver:
    """Fixed-point sweeps over the members of each algebraic loop (see the module docstring).

    Parameters
    ----------
    groups : sequence of sequence of tuple
        Per loop, its members in stepping order, each as ``(slot, inst, in_buf, in_buf_addr,
        in_vr_addr, n_in, out_vr_addr, n_out, out_offset_bytes, feeds)`` with ``feeds``
        ``[(input index, source column, factor, offset), ...]`` (the raw FMI layout of
        :mod:`orchestrator.cosim.master`).
    names : sequence of sequence of str
        The component names of each loop (for messages).
    tolerance : float
        Largest move of an input in the last sweep, relative to ``max(1, |u|)``.
    max_iterations : int
        Sweeps per communication point.
    stop : type
        Exception raised as ``stop(slot, function, status, k)`` on a failing FMI status.
    """

    def __init__(self, groups: Sequence[Sequence[tuple]], names: Sequence[Sequence[str]], tolerance: float,
                 max_iterations: int, stop: type) -> None:
        self.groups = [[_Member(*m) for m in group] for group in groups]
        self.names = [", ".join(n) for n in names]
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
        tol, stop = self.tolerance, self.stop
        for g, group in enumerate(self.groups):
            moved = 0.0
            for _ in range(self.max_iterations):
                moved = 0.0
                for m in group:
                    buf = m.buf
                    for j, col, factor, offset in m.feeds:
                        u = factor * row[col] + offset
                        change = abs(u - buf[j]) / max(1.0, abs(u))
                        if not change <= moved:  # also a NaN, which never converges
                            moved = change if change == change else math.inf
                        buf[j] = u
                    inst = m.inst
                    if m.n_in:
                        st = inst.set_real(inst.component, m.vr_in, m.n_in, m.buf_addr)
                        if st > 1:
                            raise stop(m.slot, "fmi2SetReal", st, k)
                    if m.n_out:
                        st = inst.get_real(inst.component, m.vr_out, m.n_out, address + m.out_offset_bytes)
                        if st > 1:
                            raise stop(m.slot, "fmi2GetReal", st, k)
                if moved <= tol:
                    break
            else:
                raise LoopNotConverged(k, f"the algebraic loop through {self.names[g]} did not converge at t = "
                                          f"{t:.6g} s: an input still moved by {moved:.3g} (relative) after "
                                          f"{self.max_iterations} sweeps (simulation.loop_max_iterations; the loop's "
                                          f"gain must be below 1 in magnitude for the iteration to converge)")


def loop_groups(plan: Sequence[tuple], loops: Sequence[Sequence[str]], slot_names: Sequence[str]) -> list[list[tuple]]:
    """The solver's member tuples of each loop from the interpreted step loop's plan entries.

    ``plan`` entries are ``(i, inst, buf, buf_addr, vr_in, n_in, vr_out, n_out, n_couple,
    out_offset_bytes, feeds, lin_feeds, ...)`` in stepping order; ``feeds`` ``(j, upstream,
    col)`` and ``lin_feeds`` ``(j, upstream, col, factor, offset)``.
    """
    out = []
    for loop in loops:
        members = set(loop)
        group = []
        for entry in plan:
            i, inst, buf, buf_addr, vr_in, n_in, vr_out, n_out, _, offset, feeds, lin_feeds = entry[:12]
            if slot_names[i] not in members:
                continue
            all_feeds = sorted([(j, col, 1.0, 0.0) for j, _, col in feeds]
                               + [(j, col, factor, shift) for j, _, col, factor, shift in lin_feeds])
            group.append((i, inst, buf, buf_addr, vr_in, n_in, vr_out, n_out, offset, all_feeds))
        out.append(group)
    return out

