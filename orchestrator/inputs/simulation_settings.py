"""The time grid and master algorithm of a scenario (its ``[simulation]`` table), validated.

:class:`SimulationSettings` is part of a :class:`~orchestrator.inputs.scenario.Scenario`
(and imported from there); a mistake raises :class:`~orchestrator.errors.ScenarioError`
naming the ``simulation.*`` key.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from components.validation import is_number

from ..errors import ScenarioError
from .limits import MAX_LOOP_ITERATIONS, MIN_RELATIVE_STEP
from .master_options import ALGEBRAIC_LOOPS, ALGORITHMS, EXTRAPOLATIONS

#: relative tolerance when checking that times are whole multiples of the step
_MULTIPLE_RTOL = 1e-9


def steps_between(duration_s: float, step_s: float) -> int | None:
    """``duration / step`` if it is a whole number (relative tolerance 1e-9), else None (also when not finite)."""
    ratio = duration_s / step_s
    if not math.isfinite(ratio):
        return None
    n = round(ratio)
    if n >= 0 and abs(ratio - n) <= _MULTIPLE_RTOL * max(1.0, abs(ratio)):
        return int(n)
    return None


@dataclass(frozen=True)
class SimulationSettings:
    """Time grid and master algorithm.

    Parameters
    ----------
    stop_s : float
        Stop time [s] (> start, a whole number of steps after it).
    step_s : float
        Communication step H [s] (> 0).
    start_s : float
        Start time [s].
    output_interval_s : float, optional
        Sampling interval of the recorded variables [s], a whole multiple of the
        step; default: the step.
    window_s : (float, float), optional
        Analysis window of the statistics [s]; default ``(start, stop)``.
    algorithm : {"gauss-seidel", "jacobi"}
        Master algorithm.
    extrapolation : {"hold", "linear"}
        How coupled inputs are formed from the sources' samples (see
        :mod:`orchestrator.cosim.master`).
    order : tuple of str, optional
        Stepping order of the components; default from the connection graph.
    algebraic_loops : {"refuse", "iterate"}
        A cycle of direct-feedthrough dependencies is refused when the system is
        checked, or solved at every communication point by fixed-point iteration
        (:mod:`orchestrator.cosim.algebraic_loops`).
    loop_tolerance : float
        Convergence of that iteration: every loop input moves by at most
        ``loop_tolerance * max(1, |u|)`` in the last sweep (> 0, < 1).
    loop_max_iterations : int
        Sweeps per communication point before the run fails there (>= 1).
    """

    stop_s: float
    step_s: float
    start_s: float = 0.0
    output_interval_s: float | None = None
    window_s: tuple[float, float] | None = None
    algorithm: str = "gauss-seidel"
    extrapolation: str = "hold"
    order: tuple[str, ...] | None = None
    algebraic_loops: str = "refuse"
    loop_tolerance: float = 1e-10
    loop_max_iterations: int = 100

    def __post_init__(self) -> None:
        for key, value in (("simulation.start", self.start_s), ("simulation.stop", self.stop_s), ("simulation.step", self.step_s)):
            if not is_number(value) or not math.isfinite(value):
                raise ScenarioError(key, value, "a finite number [s]")
        start, stop, step = float(self.start_s), float(self.stop_s), float(self.step_s)
        if not step > 0.0:
            raise ScenarioError("simulation.step", self.step_s, "> 0 s")
        if not stop > start:
            raise ScenarioError("simulation.stop", self.stop_s, f"> simulation.start = {start:g} s")
        length = stop - start
        if not math.isfinite(length):
            raise ScenarioError("simulation.stop", self.stop_s, f"a run whose length stop - start is a finite number "
                                f"(start = {start:g} s)")
        if step > length:
            raise ScenarioError("simulation.step", self.step_s, f"a step no longer than the run, stop - start = {length:g} s")
        finest = MIN_RELATIVE_STEP * max(abs(start), abs(stop))
        if step < finest:
            raise ScenarioError("simulation.step", self.step_s,
                                f"a step of at least {MIN_RELATIVE_STEP:g} x max(|start|, |stop|) = {finest:g} s (finer "
                                "communication points are not distinct in double precision)")
        if steps_between(length, step) is None:
            raise ScenarioError("simulation.step", self.step_s, f"a step that divides stop - start = {length:g} s into whole steps")
        out = step if self.output_interval_s is None else self.output_interval_s
        if not is_number(out) or not math.isfinite(out) or not out > 0:
            raise ScenarioError("simulation.output_interval", self.output_interval_s, "a number > 0 [s]")
        if out > length * (1.0 + _MULTIPLE_RTOL):
            raise ScenarioError("simulation.output_interval", self.output_interval_s,
                                f"an interval no longer than the run, stop - start = {length:g} s")
        if steps_between(float(out), step) in (None, 0):
            raise ScenarioError("simulation.output_interval", self.output_interval_s, f"a whole multiple of the step {step:g} s")
        window = (start, stop) if self.window_s is None else self.window_s
        if (not isinstance(window, (tuple, list)) or len(window) != 2 or not all(is_number(w) for w in window)):
            raise ScenarioError("simulation.window", self.window_s, "[begin, end] in seconds")
        w0, w1 = float(window[0]), float(window[1])
        if not (start <= w0 < w1 <= stop):
            raise ScenarioError("simulation.window", list(window), f"start <= begin < end <= stop, i.e. within [{start:g}, {stop:g}] s")
        if self.algorithm not in ALGORITHMS:
            raise ScenarioError("simulation.algorithm", self.algorithm, "one of " + ", ".join(ALGORITHMS))
        if self.extrapolation not in EXTRAPOLATIONS:
            raise ScenarioError("simulation.extrapolation", self.extrapolation, "one of " + ", ".join(EXTRAPOLATIONS))
        if self.algebraic_loops not in ALGEBRAIC_LOOPS:
            raise ScenarioError("simulation.algebraic_loops", self.algebraic_loops, "one of " + ", ".join(ALGEBRAIC_LOOPS))
        if not is_number(self.loop_tolerance) or not 0.0 < float(self.loop_tolerance) < 1.0:
            raise ScenarioError("simulation.loop_tolerance", self.loop_tolerance, "a number > 0 and < 1")
        if isinstance(self.loop_max_iterations, bool) or not isinstance(self.loop_max_iterations, int) \
                or not 1 <= self.loop_max_iterations <= MAX_LOOP_ITERATIONS:
            raise ScenarioError("simulation.loop_max_iterations", self.loop_max_iterations,
                                f"a whole number from 1 to {MAX_LOOP_ITERATIONS}")
        object.__setattr__(self, "loop_tolerance", float(self.loop_tolerance))
        order = None if self.order is None else tuple(self.order)
        if order is not None and not all(isinstance(o, str) for o in order):
            raise ScenarioError("simulation.order", self.order, "a list of component names")
        object.__setattr__(self, "start_s", start)
        object.__setattr__(self, "stop_s", stop)
        object.__setattr__(self, "step_s", step)
        object.__setattr__(self, "output_interval_s", float(out))
        object.__setattr__(self, "window_s", (w0, w1))
        object.__setattr__(self, "order", order)

    @property
    def n_steps(self) -> int:
        """Number of communication steps from start to stop."""
        return steps_between(self.stop_s - self.start_s, self.step_s)

    @property
    def output_stride(self) -> int:
        """Communication steps per recorded sample."""
        return steps_between(self.output_interval_s, self.step_s)
