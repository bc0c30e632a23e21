"""The fixed-step master: Gauss-Seidel or Jacobi, with hold or linear inputs.

:class:`CoSimulation` runs a :class:`~orchestrator.cosim.resolved.ResolvedSystem`:
it instantiates the FMUs, initialises them (:mod:`orchestrator.cosim.initialisation`),
builds the run's stepping plan (:mod:`orchestrator.cosim.stepping.plan`), steps it
block by block with one of the plan's two executors, hands every finished block of
rows to the run's sink (:mod:`orchestrator.cosim.rows`) and returns a
:class:`~orchestrator.cosim.outcome.RunOutcome`.

Time
----
Communication points are ``t_k = t0 + k H`` computed from the integer step count
``k`` (no accumulated sum). Step ``k`` advances every FMU from ``t_k`` to
``t_{k+1}`` with ``fmi2DoStep(t_k, H)``.

Algorithms
----------
Gauss-Seidel (default) steps the components one after the other in the stepping
order; an input whose source was already stepped in this communication step
receives the source's new value (at ``t_{k+1}``), the others the value at
``t_k``. The default order (:func:`orchestrator.cosim.graph.dependency_order`) steps
receivers before their sources across feedback loops, so new values flow only
inside loops (the paper's system: gearbox, generator, wind), and an FMU whose
outputs depend directly on its inputs just before the consumers of those outputs
(a pass-through changes nothing). Jacobi sets every input from the values at
``t_k`` and then steps all components. Where the order delays a connection by a
step the run says so (:mod:`orchestrator.cosim.coupling_delays`).

Input values
------------
FMI 2.0 inputs are held over a step (pythonfmu FMUs do not support
``fmi2SetRealInputDerivatives``). ``hold`` sets each input to its source's latest
sample. ``linear`` sets it to the straight line through the source's two latest
samples evaluated at the middle of the receiving step, ``t_k + H/2``: the
constant with the same mean over the step as the linearly extrapolated signal.
With samples at ``t_{k+1}`` and ``t_k`` (Gauss-Seidel, source already stepped)
that is their mean; with samples at ``t_k`` and ``t_{k-1}`` it is
``1.5 y_k - 0.5 y_{k-1}``.

The stepping loop
-----------------
Per FMU and step the loop makes one ``fmi2SetReal`` (if the FMU has connected
inputs), one ``fmi2DoStep`` and one ``fmi2GetReal`` that reads the coupling
outputs and, on sampling steps, the recorded variables, calling the raw C
functions with pre-built value-reference arrays (:mod:`orchestrator.cosim.fmi_runtime`).
``fmi2GetReal`` writes straight into the row buffer
(:class:`~orchestrator.cosim.stepping.plan.RowBuffers`: a block of
:data:`BLOCK_STEPS` + 2 rows, or a three-row ring when not every step is sampled)
and the coupled inputs are read from there: no per-step Python objects, no copies.
What each step does is one named :class:`~orchestrator.cosim.stepping.plan.StepPlan`,
built once per run, with two executors that make the same calls with the same
values in the same order (the tests compare their recorded values exactly):

* :class:`~orchestrator.cosim.stepping.compiled_loop.CompiledLoop` (the default
  wherever it can run: numba or its ahead-of-time build available, every FMU a
  PythonFMU with Real variables only, no profiling, no iterated algebraic loop)
  runs whole blocks of steps in compiled code;
* :class:`~orchestrator.cosim.stepping.python_loop.PythonLoop` runs the plan in
  plain Python: any FMU (a C FMU's calls release the GIL), typed ports, algebraic
  loops, profiling.

Measured with three trivial PythonFMUs (``python benchmarks/bench_plumbing.py
--repeat 5``, medians of 5 runs per algorithm/extrapolation variant, on a shared,
noisy 2-core machine): the bare FMI calls of a hand-written Python loop cost
15.5 us per step; the compiled loop 6.1-8.0 us (below that floor: no ctypes and no
Python per call); the Python loop 15.8-23.8 us, i.e. 0.3-8.3 us (median 2.7 us)
above the floor, where the exec-generated loop it replaced measured 1.0-4.5 us
(median 2.0 us) in the same benchmark of the previous version.

Types
-----
Real variables are exchanged as above; Integer, Enumeration, Boolean and String
variables through :class:`~orchestrator.cosim.values.TypedPorts` (two more calls
per step for an FMU that has such ports, none otherwise). Connection
transformations (SSP) are applied where the value is exchanged. String samples are
kept for the whole run (:class:`~orchestrator.cosim.values.TextStore`; only FMUs
with String outputs have any).

Results
-------
After each block of steps its finished rows go to the run's sink (a
:class:`~orchestrator.cosim.rows.RowSink`, e.g. a results file writer of
:mod:`orchestrator.run.writers`) and, unless ``keep_values`` is off, into the
outcome's arrays; the block buffer is then reused, so the master's own memory does
not grow with the run.

Stopping
--------
An FMU status worse than warning stops the run with an :class:`FmuStepError`
message (FMU, function, time, status, the FMU's log); SIGINT (Ctrl-C), SIGTERM
and SIGHUP set a flag (:class:`~orchestrator.cosim.stop_requests.StopRequests`)
that is checked after each FMU is instantiated and between blocks of steps; a
sink that cannot write (``OSError``: a full disk) stops the run too. Either way
the samples recorded so far are returned with ``complete = False``; a stop
request before the first step raises :class:`~orchestrator.errors.RunInterrupted`.
An FMU that ends the simulation itself (``fmi2Discard`` with ``fmi2Terminated``
after progress, :mod:`orchestrator.cosim.termination`) ends the run normally:
``complete = True``, ``ended_by`` naming it, its last sample kept (also off the
output grid).
"""

from __future__ import annotations

import math
import time
from typing import Callable

import numpy as np

from ..errors import FmuStepError, InitializationError
from .algebraic_loops import LoopNotConverged, LoopSolver
from .fmi_runtime import FmuInstance
from .initialisation import bound_values, initialise
from .outcome import RunOutcome
from .resolved import ResolvedSystem
from .rows import FinishedRows, RowSink
from .stepping.compiled_loop import CompiledLoop, unavailable_reason
from .stepping.plan import RowBuffers, StepFailed, StepPlan, build_plan
from .stepping.python_loop import TIMED_FUNCTIONS, ProfiledLoop, PythonLoop
from .stop_requests import StopRequests
from .termination import discard_status
from .values import TextStore

#: executors of the stepping plan: ``auto`` (the compiled loop where it can run, else the Python loop),
#: ``compiled`` (an error where it cannot run), ``python``
STEP_LOOPS = ("auto", "compiled", "python")
#: earlier names of :data:`STEP_LOOPS`, still accepted (the generated loop they named is gone: same values)
STEP_LOOP_ALIASES = {"numba": "compiled", "interpreted": "python", "generated": "python"}
#: steps between checks for stop requests, progress updates and hand-overs of rows to the sink
BLOCK_STEPS = 250


class CoSimulation:
    """Run a :class:`~orchestrator.cosim.resolved.ResolvedSystem` with the fixed-step master.

    Parameters
    ----------
    system : ResolvedSystem
        Checked scenario (settings: algorithm, extrapolation, step, times, recording).
    profile : bool
        Time every Real FMI call of the stepping loop per FMU (:attr:`RunOutcome.profile`;
        runs the Python loop).
    step_loop : {"auto", "compiled", "python"}
        Executor of the stepping plan. ``auto`` (default): the compiled loop
        (:mod:`orchestrator.cosim.stepping.compiled_loop`) where it can run, else the
        Python loop; ``compiled``: the compiled loop or a ValueError saying why not;
        ``python``: :mod:`orchestrator.cosim.stepping.python_loop`. Both make the same
        FMI calls with the same values. The earlier names ``numba``, ``generated`` and
        ``interpreted`` are accepted (:data:`STEP_LOOP_ALIASES`).
    """

    def __init__(self, system: ResolvedSystem, profile: bool = False, step_loop: str = "auto") -> None:
        choice = STEP_LOOP_ALIASES.get(step_loop, step_loop)
        if choice not in STEP_LOOPS:
            raise ValueError(f"step_loop {step_loop!r}: expected one of {', '.join(STEP_LOOPS)}")
        self.system = system
        self.profile = bool(profile)
        self.step_loop = choice
        self.settings = system.scenario.simulation
        self.instances: dict[str, FmuInstance] = {}
        self._ended: tuple[str, float] | None = None  # (FMU, time) when an FMU terminated the run

    # ------------------------------------------------------------------ run
    def run(self, progress: Callable[[int, int], None] | None = None, handle_sigint: bool = True,
            wall_time_limit_s: float | None = None, *, sink: RowSink | None = None, keep_values: bool = True,
            stop: StopRequests | None = None) -> RunOutcome:
        """Instantiate, initialise, step to the stop time and free the FMUs.

        Parameters
        ----------
        progress : callable(done_steps, total_steps), optional
            Called every :data:`BLOCK_STEPS` steps.
        handle_sigint : bool
            Without ``stop``: catch SIGINT, SIGTERM and SIGHUP for the duration of
            the run (main thread only) and return the partial results instead of
            dying; False: leave the process's signal handling alone.
        wall_time_limit_s : float, optional
            Stop stepping (between blocks of steps) once the run has taken this
            much wall-clock time [s]; the outcome is then incomplete, with an error
            naming the limit and the time reached. None or 0: no limit.
        sink : RowSink, optional
            Receives every finished block of rows as the run goes (row 0, at the
            start time, first).
        keep_values : bool
            Also keep every row in the outcome's ``time_s``/``values`` (default;
            memory grows with the rows recorded so far). False: the outcome holds
            no rows (the sink has them).
        stop : StopRequests, optional
            A caller's active stop requests (the caller installed the handlers,
            e.g. for a whole run with its result files); checked after each FMU
            is instantiated and between blocks of steps.

        Returns
        -------
        RunOutcome
            Also when an FMU fails, the sink cannot write or the run is
            interrupted while stepping (``complete`` False).

        Raises
        ------
        FmuStepError, InitializationError
            If instantiation or initialisation fails (nothing to record yet).
        RunInterrupted
            If a stop was requested before the first step.
        """
        if stop is None:
            with StopRequests(enabled=handle_sigint) as own:
                return self._run(progress, wall_time_limit_s, sink, keep_values, own)
        return self._run(progress, wall_time_limit_s, sink, keep_values, stop)


    def _run(self, progress, wall_time_limit_s, sink, keep_values, stop: StopRequests) -> RunOutcome:
        wall0, cpu0 = time.perf_counter(), time.process_time()
        sim = self.settings
        n_rows = sim.n_steps // sim.output_stride + 2  # + 1: a last sample off the output grid (an FMU ended the run)
        self._ended = None
        loop_time = loop_cpu = 0.0
        try:
            self._instantiate(stop)
            start_values = initialise(self.system, self.instances, transferred=True)
            initial_values = bound_values(self.system, start_values)
            stop.raise_if_requested("initialisation", sim.start_s)
            plan = build_plan(self.system, self.instances)
            buffers = RowBuffers.allocate(plan.n_columns, plan.stride, BLOCK_STEPS)
            text = TextStore(n_rows, plan.n_text)
            timers = np.zeros((len(plan.fmus), len(TIMED_FUNCTIONS))) if self.profile else None
            loop = self._step_loop(plan, buffers, text, timers)
            first = self._first_row(plan, text, loop.loop_solver)
            buffers.start(first)
            rows = FinishedRows(sim.start_s, sim.step_s * plan.stride, plan.recorded_columns,
                                n_rows if keep_values else 0, sink, text=text, text_columns=plan.text_columns)
            error = rows.deliver(first[None, :])
            k_done, stage = 0, "writing"
            if error is None:
                loop0, loop_cpu0 = time.perf_counter(), time.process_time()
                deadline = wall0 + wall_time_limit_s if wall_time_limit_s else math.inf
                k_done, error, stage = self._step_blocks(loop, plan, buffers, text, rows, progress, stop, deadline,
                                                         wall_time_limit_s)
                loop_time, loop_cpu = time.perf_counter() - loop0, time.process_time() - loop_cpu0
        finally:
            self._close()
        interrupted = stage == "interrupted"
        kept = rows.count if rows.kept is not None else 0
        return RunOutcome(
            time_s=rows.time_s(),
            values=rows.values(),
            columns=tuple(self.system.recorded),
            complete=error is None,
            steps=k_done,
            stopped_at_s=sim.start_s + k_done * sim.step_s,
            error=error,
            interrupted=interrupted,
            wall_time_s=time.perf_counter() - wall0,
            loop_time_s=loop_time,
            cpu_time_s=time.process_time() - cpu0,
            loop_cpu_time_s=loop_cpu,
            initial_values=initial_values,
            start_values=start_values,
            fmu_log={name: list(inst.log) for name, inst in self.instances.items()},
            profile=None if timers is None else {
                fmu.name: dict(zip(TIMED_FUNCTIONS, map(float, row))) for fmu, row in zip(plan.fmus, timers)
            },
            stop_signal=stop.signal_name if interrupted else None,
            stage="stepping" if interrupted else stage,
            text={self.system.recorded[j].column: text.rows[:kept, col].copy()
                  for j, col in plan.text_columns.items()},
            ended_by=None if self._ended is None else self._ended[0],
        )

    def initial_values(self, transferred: bool = False) -> dict[str, float]:
        """Instantiate and initialise the FMUs, return what the initial bindings set, free the FMUs.

        Parameters
        ----------
        transferred : bool
            Also the values the connected inputs get in initialisation.

        Returns
        -------
        dict of str -> float
            ``{"component.parameter": value}`` for every ``[[initial]]`` binding (with
            ``transferred``: also ``{"component.input": value}`` for every connected input).
        """
        try:
            self._instantiate()
            return initialise(self.system, self.instances, transferred)
        finally:
            self._close()

    # ----------------------------------------------------------- lifecycle
    def _instantiate(self, stop: StopRequests | None = None) -> None:
        sim = self.settings
        sc = self.system.scenario
        for name in self.system.init_order:
            if stop is not None:
                stop.raise_if_requested("instantiation", sim.start_s)
            inst = FmuInstance(name, self.system.interfaces[name])
            self.instances[name] = inst
            inst.instantiate(sim.start_s, sim.stop_s)
            params = dict(sc.component(name).parameters)
            if params:
                inst.set_values(params, sim.start_s)
            inst.enter_initialization(sim.start_s)
        if stop is not None:
            stop.raise_if_requested("instantiation", sim.start_s)

    def _close(self) -> None:
        for inst in self.instances.values():
            inst.close()

    # ------------------------------------------------------------ stepping
    def _step_loop(self, plan: StepPlan, buffers: RowBuffers, text: TextStore,
                   timers: np.ndarray | None) -> PythonLoop | CompiledLoop:
        """The executor :attr:`step_loop` chooses for this plan (see the class docstring)."""
        sim = self.settings
        loops = self.system.algebraic_loops
        if self.step_loop in ("auto", "compiled"):
            reason = unavailable_reason(plan, profiling=timers is not None, iterating_loops=bool(loops))
            if reason is None:
                return CompiledLoop(plan, buffers, text)
            if self.step_loop == "compiled":
                raise ValueError(f"step_loop 'compiled' cannot run this system: {reason}")
        solver = LoopSolver(plan, loops, sim.loop_tolerance, sim.loop_max_iterations, StepFailed) if loops else None
        if timers is not None:
            return ProfiledLoop(plan, buffers, text, timers, solver)
        return PythonLoop(plan, buffers, text, solver)

    def _first_row(self, plan: StepPlan, text: TextStore, solver: LoopSolver | None) -> np.ndarray:
        """Every output at the start time, after initialisation (algebraic loops solved there)."""
        t0 = self.settings.start_s
        first = np.full(plan.n_columns, np.nan)
        for fmu in plan.fmus:
            if fmu.outputs:
                first[fmu.column:fmu.column + fmu.n_outputs] = fmu.instance.get_reals(fmu.outputs, t0)
            if fmu.ports is not None:
                fmu.ports.read_initial(first, text, t0)
        if solver is not None:
            try:
                solver.solve(first, 0, t0)
            except LoopNotConverged as exc:
                raise InitializationError(str(exc)) from None
        return first

    def _step_blocks(self, loop, plan: StepPlan, buffers: RowBuffers, text: TextStore, rows: FinishedRows,
                     progress, stop: StopRequests, deadline: float = math.inf,
                     wall_time_limit_s: float | None = None) -> tuple[int, str | None, str]:
        """Step block by block until the stop time, an FMU failure or termination, a stop request, a sink error
        or the deadline.

        After each block its finished rows go to ``rows`` and the buffers are rewound.
        Returns (communication steps completed, error message or None, stage:
        ``"stepping"``, ``"interrupted"`` or ``"writing"``).
        """
        t0, H, n_steps = self.settings.start_s, self.settings.step_s, self.settings.n_steps
        k = 0
        error = None
        try:
            while k < n_steps:
                if stop.requested:
                    return k, f"{stop.reason} at t = {t0 + k * H:.6g} s", "interrupted"
                k_start = k
                try:
                    k = loop.advance(k, min(n_steps, k + BLOCK_STEPS), t0, H)
                except StepFailed as failed:
                    k, error = self._stopped(loop, plan, failed, k_start, t0, H)
                except LoopNotConverged as diverged:  # samples up to t_k are kept
                    k, error = diverged.k, str(diverged)
                done, off_grid = buffers.finished(k_start, k, self._ended is not None, text)
                write_error = rows.deliver(done, t0 + k * H if off_grid else None)
                if write_error is not None:
                    return k, f"{write_error} at t = {t0 + k * H:.6g} s", "writing"
                if error is not None or self._ended is not None:
                    return k, error, "stepping"
                buffers.rewind(k_start, k)
                if progress is not None:
                    progress(k, n_steps)
                if k < n_steps and time.perf_counter() > deadline:
                    return k, f"wall-time limit of {wall_time_limit_s:g} s reached at t = {t0 + k * H:.6g} s", \
                        "stepping"
        except KeyboardInterrupt:  # a second signal, or no handler outside the main thread
            return k, f"{stop.reason} at t = {t0 + k * H:.6g} s", "interrupted"
        return k, error, "stepping"

    def _stopped(self, loop, plan: StepPlan, failed: StepFailed, k_start: int, t0: float,
                 H: float) -> tuple[int, str | None]:
        """(steps completed, error or None) after a failing status; None and ``self._ended`` set when an FMU
        ended the simulation (:mod:`orchestrator.cosim.termination`)."""
        inst = plan.fmus[failed.slot].instance
        discard = discard_status(inst, failed.function, failed.status, t0 + failed.k * H, t0 + (failed.k + 1) * H)
        if discard is not None and discard.ends_run:  # the FMU ended the simulation
            try:
                k = loop.finish_step(failed.k, failed.slot, t0, H, k_start) if discard.reached_step_end \
                    else failed.k
            except StepFailed as second:
                failed, discard = second, None
                inst = plan.fmus[failed.slot].instance
            else:
                self._ended = (inst.name, t0 + k * H)
                return k, None
        inst.mark_failed(failed.status)
        error = str(FmuStepError(inst.name, failed.function, t0 + failed.k * H, failed.status, list(inst.log)))
        if discard is not None:
            error += discard.note()
        return failed.k, error
