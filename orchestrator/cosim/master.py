"""Fixed-step master algorithms: Gauss-Seidel and Jacobi, with hold or linear inputs.

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
``t_k``. The default order (:func:`orchestrator.cosim.graph.stepping_order`) steps
receivers before their sources across feedback loops, so new values flow only
inside loops (the paper's system: gearbox, generator, wind). Jacobi sets every
input from the values at ``t_k`` and then steps all components.

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

Initialisation
--------------
All FMUs are instantiated, their scenario parameter values set, and they enter
initialisation mode. Then the master sweeps the components in dependency order
(connections and ``[[initial]]`` bindings; the paper's system: wind, gearbox,
generator), setting each component's connected inputs and bound parameters from
its sources' current outputs (read in initialisation mode): wind ``omega(t0)`` ->
gearbox ``omega_rotor`` -> gearbox ``omega_out`` -> generator initial speed.
Sweeps repeat until no transferred value changes (a fixed point; feedback loops
need one extra sweep), then every FMU exits initialisation mode and all outputs
are read at ``t0``.

Speed
-----
Per FMU and step the loop makes one ``fmi2SetReal`` (if the FMU has connected
inputs), one ``fmi2DoStep`` and one ``fmi2GetReal`` that reads the coupling
outputs and, on sampling steps, the recorded variables, calling the C functions
through this project's own prototypes with pre-built value-reference arrays
(:mod:`orchestrator.cosim.fmi_runtime`; a PythonFMU's functions are called without
releasing the GIL, which its wrapper would take back at once). ``fmi2GetReal`` writes straight into a
block buffer of :data:`BLOCK_STEPS` + 2 rows (or, when not every step is sampled,
into a three-row ring buffer copied into the block's sample rows on sampling
steps), and the coupled inputs are read from there: no per-step Python objects,
no copies. The loop is
generated and compiled per system (:func:`compile_step_loop`), with every FMI
function, array and column offset bound to a name, so each coupling is one
statement. That pays: above the floor of the bare FMI calls, the generated loop
costs 0.7-1.3 us per step for three trivial FMUs, the same loop as plain Python
over the slots (:func:`interpreted_step_loop`, kept as the reference the
generated one is tested against) 2.3-3.2 us, in all four algorithm/extrapolation
variants (``python benchmarks/bench_plumbing.py --repeat 7``, medians; the
floor itself is ~12 us).

Types
-----
Real variables are exchanged by the statements above; Integer, Enumeration,
Boolean and String variables through :class:`~orchestrator.cosim.values.TypedPorts`
(two more calls per step for an FMU that has such ports, none otherwise, so a
Real-only system runs exactly the loop it always ran). Connection transformations
(SSP) are applied where the value is exchanged: a linear one inside the Real
statement of that coupling only. String samples are kept for the whole run
(:class:`~orchestrator.cosim.values.TextStore`; only FMUs with String outputs
have any).

Results
-------
After each block of steps its finished rows go to the run's sink (a
:class:`RowSink`, e.g. a results file writer of :mod:`orchestrator.run.writers`)
and, unless ``keep_values`` is off, into the outcome's arrays; the block buffer
is then reused, so the master's own memory does not grow with the run.

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

import ctypes
import math
import time
from ctypes import c_double
from dataclasses import dataclass, field
from typing import Callable, Protocol, Sequence

import numpy as np

from ..atomic_files import describe_os_error
from ..errors import FmuStepError, InitializationError
from .algebraic_loops import LoopNotConverged, LoopSolver, loop_groups
from .fmi_runtime import FmuInstance, value_references
from .stop_requests import StopRequests
from .system import RecordedVariable, ResolvedSystem
from .termination import discard_status
from .values import TextStore, TypedPorts

#: stepping-loop implementations: ``auto`` (the compiled loop where it can run, else the generated one),
#: ``numba`` (:mod:`orchestrator.cosim.compiled_loop`, an error where it cannot run), ``generated``
#: (:func:`compile_step_loop`), ``interpreted`` (:func:`interpreted_step_loop`)
STEP_LOOPS = ("auto", "numba", "generated", "interpreted")
#: steps between checks for stop requests, progress updates and hand-overs of rows to the sink
BLOCK_STEPS = 250
#: maximum initialisation sweeps beyond the number of components
EXTRA_INIT_SWEEPS = 2


@dataclass
class RunOutcome:
    """What a co-simulation run produced.

    Attributes
    ----------
    time_s : ndarray, shape (n,)
        Sample times [s].
    values : ndarray, shape (n, m)
        Recorded variables, columns as ``columns``.
    columns : tuple of RecordedVariable
    complete : bool
        True if the run reached the stop time.
    steps : int
        Communication steps completed (the samples cover the sampled ones among them).
    stopped_at_s : float
        Time of the last completed communication point [s].
    error : str or None
        Why the run stopped early (FMU failure, interruption, a results file that could not be written).
    interrupted : bool
        True if stopped by a signal (Ctrl-C, SIGTERM, SIGHUP).
    stop_signal : str or None
        Name of that signal (``"SIGINT"``, ...).
    stage : str
        Where the run ended: ``"stepping"`` (also when complete), ``"writing"`` (the sink failed),
        or, for outcomes built by a caller after an exception, ``"instantiation"``/``"initialisation"``.
    wall_time_s : float
        Whole run: instantiation, initialisation, stepping, cleanup [s].
    loop_time_s : float
        Stepping loop only [s].
    cpu_time_s, loop_cpu_time_s : float
        Process CPU time [s] of the whole run and of the stepping loop (the FMUs run in
        this process, so it includes their work; use it for benchmarks on a shared machine).
    initial_values : dict of str -> float
        Values transferred by the initialisation sweeps (``"generator.omega0"`` ...).
    fmu_log : dict of str -> list of str
        Last log messages of each FMU.
    profile : dict of str -> dict of str -> float, optional
        With profiling on: seconds spent in each FMI function per component,
        ``{"gearbox": {"fmi2SetReal": ..., "fmi2DoStep": ..., "fmi2GetReal": ...}}``.
    text : dict of str -> ndarray of object
        Samples of the recorded String variables by column name (their ``values``
        column is NaN); Integer, Enumeration and Boolean columns are in ``values``
        as exact floats (Boolean 0.0/1.0).
    ended_by : str or None
        The FMU that ended the run by terminating (``fmi2Discard`` with
        ``fmi2Terminated``); the run is then complete at ``stopped_at_s``.
    """

    time_s: np.ndarray
    values: np.ndarray
    columns: tuple[RecordedVariable, ...]
    complete: bool
    steps: int
    stopped_at_s: float
    error: str | None = None
    interrupted: bool = False
    wall_time_s: float = 0.0
    loop_time_s: float = 0.0
    cpu_time_s: float = 0.0
    loop_cpu_time_s: float = 0.0
    initial_values: dict[str, float] = field(default_factory=dict)
    fmu_log: dict[str, list[str]] = field(default_factory=dict)
    profile: dict[str, dict[str, float]] | None = None
    stop_signal: str | None = None
    stage: str = "stepping"
    text: dict[str, np.ndarray] = field(default_factory=dict)
    ended_by: str | None = None

    @classmethod
    def empty(cls, columns: tuple[RecordedVariable, ...], start_s: float, error: str, stage: str,
              interrupted: bool = False, stop_signal: str | None = None,
              fmu_log: dict[str, list[str]] | None = None) -> "RunOutcome":
        """The outcome of a run that stopped before its first sample (instantiation or initialisation)."""
        return cls(time_s=np.empty(0), values=np.empty((0, len(columns))), columns=tuple(columns), complete=False,
                   steps=0, stopped_at_s=start_s, error=error, interrupted=interrupted, stop_signal=stop_signal,
                   stage=stage, fmu_log=dict(fmu_log or {}))

    def column(self, name: str) -> np.ndarray:
        """Samples of ``"component.variable"`` (strings for a String variable)."""
        if name in self.text:
            return self.text[name]
        for i, c in enumerate(self.columns):
            if c.column == name:
                return self.values[:, i]
        raise KeyError(f"{name!r} was not recorded; recorded: {', '.join(c.column for c in self.columns)}")

    @property
    def names(self) -> list[str]:
        """Recorded column names."""
        return [c.column for c in self.columns]


class RowSink(Protocol):
    """Where the master hands each finished block of rows (e.g. :class:`orchestrator.run.writers.CsvWriter`)."""

    def append(self, time_s: np.ndarray, values: np.ndarray, text: dict[int, np.ndarray] | None = None) -> None:
        """Rows at ``time_s`` (n,), ``values`` (n, m) in the order of ``system.recorded``; may raise OSError.

        ``text`` (only when String variables are recorded): column index -> the n
        strings of that column (its ``values`` column is NaN).
        """


class _Stop(Exception):
    """Internal: a raw FMI call in the loop returned a failing status."""

    def __init__(self, slot: int, function: str, status: int, k: int) -> None:
        self.slot, self.function, self.status, self.k = slot, function, status, k


class _Slot:
    """Per-FMU layout in the stepping loop.

    The FMU's block of columns in the row buffer holds, in this order, its coupling
    outputs (read every step) and its other recorded variables (read on sampling
    steps); ``fmi2GetReal`` fills the block in one call.
    """

    def __init__(self, inst: FmuInstance) -> None:
        self.inst = inst
        self.name = inst.name
        self.in_names: list[str] = []
        self.out_names: list[str] = []
        self.n_couple = 0
        self.col0 = 0  # first column of the block
        self.feeds: list[tuple[int, int, int]] = []  # (input index, source slot, source column)
        self.linear: dict[int, tuple[float, float]] = {}  # input index -> (factor, offset) of a transformed connection
        self.in_vr = None
        self.in_buf = None
        self.out_vr = None
        self.ports: TypedPorts | None = None  # Integer/Enumeration/Boolean/String inputs and outputs


class CoSimulation:
    """Run a :class:`~orchestrator.cosim.system.ResolvedSystem` with the fixed-step master.

    Parameters
    ----------
    system : ResolvedSystem
        Checked scenario (settings: algorithm, extrapolation, step, times, recording).
    profile : bool
        Time every FMI call of the stepping loop per FMU (:attr:`RunOutcome.profile`).
    step_loop : {"auto", "numba", "generated", "interpreted"}
        ``auto`` (default): the compiled loop of :mod:`orchestrator.cosim.compiled_loop` where it can
        run (numba installed, PythonFMUs with Real variables only, no profiling), else
        :func:`compile_step_loop`; ``numba``: the compiled loop or a ValueError saying why not;
        ``generated``; ``interpreted``: the plain-Python reference :func:`interpreted_step_loop`.
        All make the same FMI calls with the same values.
    """

    def __init__(self, system: ResolvedSystem, profile: bool = False, step_loop: str = "auto") -> None:
        if step_loop not in STEP_LOOPS:
            raise ValueError(f"step_loop {step_loop!r}: expected one of {', '.join(STEP_LOOPS)}")
        self.system = system
        self.profile = bool(profile)
        self.step_loop = step_loop
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
        wall0 = time.perf_counter()
        cpu0 = time.process_time()
        sim = self.settings
        n_steps = sim.n_steps
        stride = sim.output_stride
        n_rows = n_steps // stride + 2  # + 1: a last sample off the output grid when an FMU ends the run
        self._ended = None
        loop_cpu = 0.0
        try:
            self._instantiate(stop)
            initial_values = self._initialize()
            stop.raise_if_requested("initialisation", sim.start_s)
            slots, columns, n_text = self._build_slots()
            keys = [(c.component, c.variable) for c in columns]
            order = np.array([keys.index((rv.component, rv.variable)) for rv in self.system.recorded], dtype=np.intp)
            n_cols = max(1, len(columns))
            if stride == 1:  # rows k_start - 1 and k_start of each block, then one row per step
                block = np.full((BLOCK_STEPS + 2, n_cols), np.nan)
                ring = block
            else:  # the block's sample rows; outputs go to a three-row ring buffer
                block = np.full((BLOCK_STEPS // stride + 2, n_cols), np.nan)
                ring = np.full((3, n_cols), np.nan)
            text = TextStore(n_rows, n_text)
            timers = np.zeros((len(slots), 3)) if self.profile else None
            advance = self._step_loop(slots, stride, block, ring, timers, text)
            # row 0: every output at t0, after initialisation
            first = np.full(n_cols, np.nan)
            for s in slots:
                if s.out_names:
                    values = s.inst.get_reals(s.out_names, sim.start_s)
                    first[s.col0:s.col0 + len(values)] = values
                if s.ports is not None:
                    s.ports.read_initial(first, text, sim.start_s)
            solver = getattr(advance, "loop_solver", None)
            if solver is not None:  # the algebraic loops at t0
                try:
                    solver.solve(first, 0, sim.start_s)
                except LoopNotConverged as exc:
                    raise InitializationError(str(exc)) from None
            ring[:] = first
            text_columns = {j: col for j, col in enumerate(self._text_columns(slots)) if col >= 0}
            rows = _Rows(sim.start_s, sim.step_s * stride, order, n_rows if keep_values else 0, sink,
                         text=text, text_columns=text_columns)
            error = rows.deliver(first[None, :])
            loop0 = time.perf_counter()
            loop_cpu0 = time.process_time()
            deadline = wall0 + wall_time_limit_s if wall_time_limit_s else math.inf
            if error is None:
                k_done, error, stage = self._loop(advance, slots, block, ring, text, rows, n_steps, stride,
                                                  progress, stop, deadline, wall_time_limit_s)
            else:
                k_done, stage = 0, "writing"
            loop_time = time.perf_counter() - loop0
            loop_cpu = time.process_time() - loop_cpu0
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
            fmu_log={name: list(inst.log) for name, inst in self.instances.items()},
            profile=None if timers is None else {
                s.name: dict(zip(("fmi2SetReal", "fmi2DoStep", "fmi2GetReal"), map(float, row)))
                for s, row in zip(slots, timers)
            },
            stop_signal=stop.signal_name if interrupted else None,
            stage="stepping" if interrupted else stage,
            text={self.system.recorded[j].column: text.rows[:kept, col].copy() for j, col in text_columns.items()},
            ended_by=None if self._ended is None else self._ended[0],
        )

    def _step_loop(self, slots, stride, block, ring, timers, text) -> Callable:
        """The ``advance`` function of :attr:`step_loop` for these slots (interpreted whenever algebraic loops are
        iterated: only it has the sweeps)."""
        sim = self.settings
        algorithm, extrapolation = sim.algorithm, sim.extrapolation
        loops = self.system.algebraic_loops
        if loops:
            if timers is not None:
                raise ValueError("profiling times the generated step loop, which does not iterate algebraic loops")
            if self.step_loop in ("numba", "generated"):
                raise ValueError(f"step_loop {self.step_loop!r} cannot iterate algebraic loops (the interpreted "
                                 f"loop does)")
            return interpreted_step_loop(slots, algorithm, extrapolation, stride, block, ring, text=text,
                                         loops=loops, loop_tolerance=sim.loop_tolerance,
                                         loop_max_iterations=sim.loop_max_iterations)
        if self.step_loop in ("auto", "numba"):
            from . import compiled_loop

            reason = compiled_loop.unavailable_reason(slots, timers)
            if reason is None:
                finish = interpreted_step_loop(slots, algorithm, extrapolation, stride, block, ring,
                                               text=text).finish_step
                return compiled_loop.compiled_step_loop(slots, algorithm, extrapolation, stride, block, ring,
                                                        _Stop, finish)
            if self.step_loop == "numba":
                raise ValueError(f"step_loop 'numba' cannot run this system: {reason}")
        make_loop = interpreted_step_loop if self.step_loop == "interpreted" else compile_step_loop
        return make_loop(slots, algorithm, extrapolation, stride, block, ring, timers, text=text)

    def _text_columns(self, slots: list[_Slot]) -> list[int]:
        """TextStore column of each recorded variable in ``system.recorded`` order (only String ones: -1 for others)."""
        store = {}
        for s in slots:
            if s.ports is not None:
                for name, typ, col in s.ports.outputs:
                    if typ == "String":
                        store[(s.name, name)] = col
        return [store.get((rv.component, rv.variable), -1) for rv in self.system.recorded]

    def initial_values(self) -> dict[str, float]:
        """Instantiate and initialise the FMUs, return what the initial bindings set, free the FMUs.

        Returns
        -------
        dict of str -> float
            ``{"component.parameter": value}`` for every ``[[initial]]`` binding.
        """
        try:
            self._instantiate()
            return self._initialize()
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

    def _initialize(self) -> dict[str, float]:
        """Sweeps in dependency order until the transferred values are a fixed point."""
        sc = self.system.scenario
        t0 = self.settings.start_s
        links = [(c.source, c.target, self.system.loop_transformation(c)) for c in sc.connections] \
            + [(b.source, b.target, None) for b in sc.initial]
        incoming: dict[str, list] = {name: [] for name in self.system.init_order}
        for src, dst, transform in links:
            incoming[dst.component].append((src, dst, transform))
        last: dict[str, float] = {}
        max_sweeps = len(self.system.init_order) + EXTRA_INIT_SWEEPS
        # iterated algebraic loops: converged within the loop tolerance (else: exactly), within their sweep limit
        loops = bool(self.system.algebraic_loops)
        tolerance = self.settings.loop_tolerance if loops else 0.0
        if loops:
            max_sweeps = max(max_sweeps, self.settings.loop_max_iterations)
        changed: list[str] = []
        for _ in range(max_sweeps):
            changed = []
            for name in self.system.init_order:
                if not incoming[name]:
                    continue
                values = {}
                for src, dst, transform in incoming[name]:
                    v = self.instances[src.component].get_values([src.variable], t0)[0]
                    if isinstance(transform, dict):
                        v = type(v)(transform.get(int(v), int(v)))
                    elif transform is not None:
                        v = transform.apply(v)
                    if isinstance(v, float) and not math.isfinite(v):
                        raise InitializationError(f"initialisation: {src} = {v!r} at t = {t0:g} s (needed by {dst})")
                    key = str(dst)
                    previous = last.get(key)
                    if previous != v and not (loops and isinstance(v, float) and isinstance(previous, float)
                                              and abs(v - previous) <= tolerance * max(1.0, abs(v))):
                        changed.append(key)
                    last[key] = v
                    values[dst.variable] = v
                self.instances[name].set_values(values, t0)
            if not changed:
                break
        else:
            hint = (" (simulation.loop_max_iterations; an algebraic loop converges only where its gain is below 1 in "
                    "magnitude)") if loops else ""
            raise InitializationError(
                f"initialisation did not reach a fixed point after {max_sweeps} sweeps{hint}; still changing: "
                f"{', '.join(changed)}"
            )
        for name in self.system.init_order:
            self.instances[name].exit_initialization(t0)
        bound = {str(b.target) for b in sc.initial}
        return {k: v for k, v in last.items() if k in bound}

    def _close(self) -> None:
        for inst in self.instances.values():
            inst.close()

    # ---------------------------------------------------------------- slots
    def _build_slots(self) -> tuple[list[_Slot], list[RecordedVariable], int]:
        """Slots in stepping order, the row-buffer columns (coupling outputs may be unrecorded), String columns.

        The Real outputs of each FMU are one block of columns (one ``fmi2GetReal``); the
        other types follow all Real blocks (:mod:`orchestrator.cosim.values`).
        """
        sysd = self.system
        sc = sysd.scenario
        slots = [_Slot(self.instances[name]) for name in sysd.order]
        by_name = {s.name: s for s in slots}

        def is_real(component: str, variable: str) -> bool:
            return self.system.interfaces[component].variables[variable].type == "Real"

        typed_out: dict[str, list[str]] = {s.name: [] for s in slots}
        for con in sc.connections:
            s = by_name[con.source.component]
            names = s.out_names if is_real(s.name, con.source.variable) else typed_out[s.name]
            if con.source.variable not in names:
                names.append(con.source.variable)
        columns: list[RecordedVariable] = []
        for s in slots:
            s.n_couple = len(s.out_names)
            for rv in sysd.recorded:
                if rv.component == s.name and rv.variable not in s.out_names:
                    if is_real(rv.component, rv.variable):
                        s.out_names.append(rv.variable)
                    elif rv.variable not in typed_out[s.name]:
                        typed_out[s.name].append(rv.variable)
            s.col0 = len(columns)
            iface = s.inst.interface
            for name in s.out_names:
                var = iface.variables[name]
                columns.append(RecordedVariable(s.name, name, var.value_reference, var.unit))
            s.out_vr = value_references(iface, s.out_names)
        typed_column: dict[tuple[str, str], int] = {}  # float column, or TextStore column for a String
        n_text = 0
        outputs: dict[str, list[tuple[str, str, int]]] = {}
        for s in slots:
            outputs[s.name] = []
            for name in typed_out[s.name]:
                var = s.inst.interface.variables[name]
                columns.append(RecordedVariable(s.name, name, var.value_reference, var.unit, var.type))
                if var.type == "String":
                    col, n_text = n_text, n_text + 1
                else:
                    col = len(columns) - 1
                typed_column[(s.name, name)] = col
                outputs[s.name].append((name, var.type, col))
        for i, s in enumerate(slots):
            incoming = [c for c in sc.connections if c.target.component == s.name
                        and is_real(c.target.component, c.target.variable)]
            s.in_names = [c.target.variable for c in incoming]
            s.in_vr = value_references(s.inst.interface, s.in_names)
            s.in_buf = (c_double * max(1, len(s.in_names)))()
            s.feeds = []
            s.linear = {}
            for j, c in enumerate(incoming):
                src = by_name[c.source.component]
                s.feeds.append((j, slots.index(src), src.col0 + src.out_names.index(c.source.variable)))
                transform = sysd.loop_transformation(c)
                if transform is not None:
                    s.linear[j] = (transform.factor, transform.offset)
            typed_in = [(c.target.variable, self.system.interfaces[s.name].variables[c.target.variable].type,
                         slots.index(by_name[c.source.component]), typed_column[(c.source.component, c.source.variable)],
                         sysd.loop_transformation(c))
                        for c in sc.connections if c.target.component == s.name
                        and not is_real(c.target.component, c.target.variable)]
            if outputs[s.name] or typed_in:
                s.ports = TypedPorts(i, s.inst, outputs[s.name], typed_in)
        return slots, columns, n_text

    # ----------------------------------------------------------------- loop
    def _loop(self, advance, slots, block, ring, text: TextStore, rows: "_Rows", n_steps, stride, progress,
              stop: StopRequests, deadline=math.inf, wall_time_limit_s=None) -> tuple[int, str | None, str]:
        """Step block by block until the stop time, an FMU failure or termination, a stop request, a sink error
        or the deadline.

        After each block its finished rows go to ``rows`` and the block buffer is
        rewound. Returns (communication steps completed, error message or None,
        stage: ``"stepping"``, ``"interrupted"`` or ``"writing"``).
        """
        t0, H = self.settings.start_s, self.settings.step_s
        direct = ring is block
        k = 0
        error = None
        stage = "stepping"
        try:
            while k < n_steps:
                if stop.requested:
                    return k, f"{stop.reason} at t = {t0 + k * H:.6g} s", "interrupted"
                k_start = k
                k_end = min(n_steps, k + BLOCK_STEPS)
                try:
                    k = advance(k, k_end, t0, H)
                except _Stop as failed:
                    k, error = self._stopped(advance, slots, failed, k_start, t0, H)
                except LoopNotConverged as diverged:  # samples up to t_k are kept
                    k, error = diverged.k, str(diverged)
                # the block's finished rows: samples at t_{k_start + 1} ... t_k
                last_time_s = None
                if direct:
                    done = block[2:k - k_start + 2]
                else:
                    n_done = k // stride - k_start // stride
                    if self._ended is not None and k % stride:  # the terminating FMU's last sample, off the grid
                        block[n_done] = ring[k % 3]
                        text.sample(k // stride + 1, k, range(text.rows.shape[1]))
                        n_done += 1
                        last_time_s = t0 + k * H
                    elif self._ended is not None and k > k_start:  # a finished last step on the grid
                        block[n_done - 1] = ring[k % 3]
                    done = block[:n_done]
                write_error = rows.deliver(done, last_time_s)
                if write_error is not None:
                    return k, f"{write_error} at t = {t0 + k * H:.6g} s", "writing"
                if error is not None or self._ended is not None:
                    return k, error, stage
                if direct:  # rows t_{k-1}, t_k start the next block
                    block[0:2] = block[k - k_start:k - k_start + 2]
                if progress is not None:
                    progress(k, n_steps)
                if k < n_steps and time.perf_counter() > deadline:
                    return k, f"wall-time limit of {wall_time_limit_s:g} s reached at t = {t0 + k * H:.6g} s", stage
        except KeyboardInterrupt:  # a second signal, or no handler outside the main thread
            return k, f"{stop.reason} at t = {t0 + k * H:.6g} s", "interrupted"
        return k, error, stage

    def _stopped(self, advance, slots, failed: "_Stop", k_start: int, t0: float, H: float) -> tuple[int, str | None]:
        """(steps completed, error or None) after a failing status; None and ``self._ended`` set when an FMU
        ended the simulation (:mod:`orchestrator.cosim.termination`)."""
        s = slots[failed.slot]
        discard = discard_status(s.inst, failed.function, failed.status, t0 + failed.k * H, t0 + (failed.k + 1) * H)
        if discard is not None and discard.ends_run:  # the FMU ended the simulation
            try:
                k = advance.finish_step(failed.k, failed.slot, t0, H, k_start) if discard.reached_step_end \
                    else failed.k
            except _Stop as second:
                failed, discard = second, None
                s = slots[failed.slot]
            else:
                self._ended = (s.name, t0 + k * H)
                return k, None
        s.inst.mark_failed(failed.status)
        error = str(FmuStepError(s.name, failed.function, t0 + failed.k * H, failed.status, list(s.inst.log)))
        if discard is not None:
            error += discard.note()
        return failed.k, error


class _Rows:
    """The rows a run has finished: handed to the sink and, optionally, kept for the outcome.

    Parameters
    ----------
    start_s, interval_s : float
        Time of row 0 and between rows [s].
    order : ndarray of int
        Block-buffer column of each recorded variable (``system.recorded`` order).
    capacity : int
        Rows to keep (0: keep none). The array is allocated uninitialised, so the
        memory is taken as rows arrive.
    sink : RowSink, optional
    text : TextStore, optional
        String samples of the run (rows by sample index).
    text_columns : dict of int -> int, optional
        Recorded column -> TextStore column of the recorded String variables.
    """

    def __init__(self, start_s: float, interval_s: float, order: np.ndarray, capacity: int,
                 sink: RowSink | None, text: TextStore | None = None,
                 text_columns: dict[int, int] | None = None) -> None:
        self.start_s, self.interval_s = start_s, interval_s
        self.order = order
        self.sink = sink
        self.count = 0
        self.kept = np.empty((capacity, len(order))) if capacity else None
        self.text = text
        self.text_columns = dict(text_columns or {})
        self.last_time_s: float | None = None  # a last row off the output grid (an FMU ended the run)

    def deliver(self, rows: np.ndarray, last_time_s: float | None = None) -> str | None:
        """Hand over ``rows`` (block-buffer columns), the last one at ``last_time_s`` if given (off the grid);
        the sink's write error as text, else None."""
        n = len(rows)
        if n == 0:
            return None
        values = rows[:, self.order]
        index = self.count + np.arange(n)
        times = self.start_s + self.interval_s * index
        if last_time_s is not None:
            times[-1] = self.last_time_s = last_time_s
        if self.kept is not None:
            self.kept[self.count:self.count + n] = values
        text = {j: self.text.rows[self.count:self.count + n, col] for j, col in self.text_columns.items()}
        self.count += n
        if self.sink is not None:
            try:
                if text:
                    self.sink.append(times, values, text)
                else:
                    self.sink.append(times, values)
            except OSError as exc:
                self.sink = None  # nothing more goes to a sink that failed
                return f"results not written: {describe_os_error(exc)}"
        return None

    def time_s(self) -> np.ndarray:
        n = self.count if self.kept is not None else 0
        times = self.start_s + self.interval_s * np.arange(n, dtype=float)
        if n and self.last_time_s is not None:
            times[-1] = self.last_time_s
        return times

    def values(self) -> np.ndarray:
        if self.kept is None:
            return np.empty((0, len(self.order)))
        return self.kept[:self.count]


def compile_step_loop(slots: list[_Slot], algorithm: str, extrapolation: str, stride: int,
                      data: np.ndarray, ring: np.ndarray, timers: np.ndarray | None = None,
                      text: TextStore | None = None) -> Callable:
    """Generate the stepping loop of one system, unrolled over its FMUs and couplings.

    The loop runs over one block of steps ``k_start <= k < k_end`` at a time.
    With every step sampled (``ring is data``), ``data`` is the block buffer: row
    ``k - k_start + 1`` holds the outputs at ``t_k``, so rows 0 and 1 hold
    ``t_{k_start - 1}`` and ``t_{k_start}`` on entry (the caller carries them over
    from the previous block; both are the initial row before the first block) and
    ``fmi2GetReal`` writes the outputs at ``t_{k+1}`` into row ``k - k_start + 2``.
    Otherwise the outputs go to row ``(k + 1) % 3`` of the three-row ``ring``, which
    is copied to row ``(k + 1) // stride - (k_start // stride + 1)`` of ``data`` on
    sampling steps. An input reads its source's column in the row of the sample it
    needs: ``t_{k+1}`` for a source already stepped in this step (Gauss-Seidel),
    ``t_k`` otherwise, and one row earlier for the second sample of ``linear``.

    Parameters
    ----------
    slots : list of _Slot
        Components in stepping order with their column blocks and feeds.
    algorithm : {"gauss-seidel", "jacobi"}
    extrapolation : {"hold", "linear"}
    stride : int
        Steps per sample.
    data : ndarray, shape (n_rows, n_cols)
        The block buffer (see above).
    ring : ndarray
        ``data`` itself (stride 1) or a (3, n_cols) ring buffer holding the latest rows.
    timers : ndarray, shape (n_slots, 3), optional
        If given, the loop adds the wall time of each FMU's fmi2SetReal, fmi2DoStep
        and fmi2GetReal calls to its row (profiling; costs ~1 us per call).
    text : TextStore, optional
        String values (needed when a slot has String ports).

    Returns
    -------
    callable
        ``advance(k_start, k_end, t0, H) -> k_end``; raises ``_Stop(slot, function, status, k)``
        on a failing FMI status. Its generated source is in ``advance.source``;
        ``advance.finish_step(k, slot, t0, H, k_start) -> k + 1`` completes step ``k`` after the
        FMU in ``slot`` ended the simulation (see :func:`interpreted_step_loop`).

    Notes
    -----
    An FMU with Integer, Enumeration, Boolean or String ports (:mod:`orchestrator.cosim.values`)
    gets two more calls per step, ``before(k, c)`` ahead of its ``fmi2SetReal`` and
    ``after(k, c)`` behind its ``fmi2GetReal`` (``c``: the block's row offset); a system of
    Real variables only has none.
    """
    n_cols = ring.shape[1]
    dsize = ctypes.sizeof(c_double)
    ns: dict[str, object] = {
        "_Stop": _Stop,
        "RING": (c_double * ring.size).from_address(ring.ctypes.data),
        "BASE": ring.ctypes.data,
        "data": data,
        "ring": ring,
        "clock": time.perf_counter,
        "T": timers,
    }
    position = {id(s): i for i, s in enumerate(slots)}
    gauss_seidel = algorithm == "gauss-seidel"
    linear = extrapolation == "linear"
    direct = ring is data

    if direct:  # rows of t_{k-1}, t_k, t_{k+1} in the block buffer
        body = ["t = t0 + k * H", f"o0 = (k + c) * {n_cols}", f"o1 = o0 + {n_cols}", f"a1 = BASE + o1 * {dsize}"]
        if linear:
            body.append(f"om = o0 - {n_cols}")
    else:
        body = ["t = t0 + k * H", f"o1 = ((k + 1) % 3) * {n_cols}", f"o0 = (k % 3) * {n_cols}",
                f"a1 = BASE + o1 * {dsize}"]
        if linear:
            body.append(f"om = ((k - 1) % 3) * {n_cols}")
    if stride > 1:
        body.append(f"sample = (k + 1) % {stride} == 0")
    for i, s in enumerate(slots):
        inst = s.inst
        ns.update({
            f"c{i}": inst.component, f"do{i}": inst.do_step, f"set{i}": inst.set_real, f"get{i}": inst.get_real,
            f"ib{i}": s.in_buf, f"IB{i}": ctypes.addressof(s.in_buf), f"keep{i}": (s.in_vr, s.out_vr),
            f"VRI{i}": ctypes.addressof(s.in_vr), f"VRO{i}": ctypes.addressof(s.out_vr),
        })
        typed_before = typed_after = False
        if s.ports is not None:
            ns[f"tb{i}"], ns[f"ta{i}"] = s.ports.bind(ring, text, stride, gauss_seidel, direct, _Stop)
            typed_before, typed_after = bool(s.ports.inputs), bool(s.ports.outputs)
        body.append(f"# {s.name}")
        for j_in, src, col in s.feeds:
            upstream = gauss_seidel and src < position[id(s)]
            latest, previous = ("o1", "o0") if upstream else ("o0", "om")
            if linear:
                a = 0.5 if upstream else 1.5
                value = f"{a!r} * RING[{latest} + {col}] + {1.0 - a!r} * RING[{previous} + {col}]"
            else:
                value = f"RING[{latest} + {col}]"
            if j_in in s.linear:  # an SSP LinearTransformation (or unit conversion) on the connection
                factor, offset = s.linear[j_in]
                value = f"{factor!r} * ({value}) + {offset!r}"
            body.append(f"ib{i}[{j_in}] = {value}")
        def timed(call: str, column: int) -> list[str]:
            if timers is None:
                return [call]
            return ["c_ = clock()", call, f"T[{i}, {column}] += clock() - c_"]

        row_offset = "c" if direct else "0"
        if typed_before:
            body.append(f"tb{i}(k, {row_offset})")
        if s.in_names:
            body.extend(timed(f"st = set{i}(c{i}, VRI{i}, {len(s.in_names)}, IB{i})", 0))
            body.append(f"if st > 1: raise _Stop({i}, 'fmi2SetReal', st, k)")
        body.extend(timed(f"st = do{i}(c{i}, t, H, 1)", 1))
        body.append(f"if st > 1: raise _Stop({i}, 'fmi2DoStep', st, k)")
        n_all, n_couple = len(s.out_names), s.n_couple
        target = f"a1 + {s.col0 * dsize}"
        if stride == 1 or n_all == n_couple:
            if n_all:
                body.extend(timed(f"st = get{i}(c{i}, VRO{i}, {n_all}, {target})", 2))
                body.append(f"if st > 1: raise _Stop({i}, 'fmi2GetReal', st, k)")
        else:
            body.extend(timed(f"st = get{i}(c{i}, VRO{i}, {n_all} if sample else {n_couple}, {target})" if n_couple else
                              f"st = get{i}(c{i}, VRO{i}, {n_all}, {target}) if sample else 0", 2))
            body.append(f"if st > 1: raise _Stop({i}, 'fmi2GetReal', st, k)")
        if typed_after:
            body.append(f"ta{i}(k, {row_offset})")
    if not direct:
        body.append("if sample:")
        body.append(f"    data[(k + 1) // {stride} - r0] = ring[(k + 1) % 3]")
    lines = ["def advance(k_start, k_end, t0, H):",
             "    c = 1 - k_start" if direct else f"    r0 = k_start // {stride} + 1",
             "    for k in range(k_start, k_end):"]
    lines += ["        " + b for b in body]
    lines.append("    return k_end")
    source = "\n".join(lines) + "\n"
    exec(compile(source, "<dtcosim step loop>", "exec"), ns)
    advance = ns["advance"]
    advance.source = source
    advance.finish_step = interpreted_step_loop(slots, algorithm, extrapolation, stride, data, ring,
                                                text=text).finish_step
    return advance


def interpreted_step_loop(slots: list[_Slot], algorithm: str, extrapolation: str, stride: int,
                          data: np.ndarray, ring: np.ndarray, timers: np.ndarray | None = None,
                          text: TextStore | None = None, loops: Sequence[Sequence[str]] = (),
                          loop_tolerance: float = 1e-10, loop_max_iterations: int = 100) -> Callable:
    """The same stepping loop as :func:`compile_step_loop`, as plain Python over the slots (no generated code).

    It makes the same FMI calls with the same values in the same order, so its
    results are identical; it exists as the reference the generated loop is
    tested against and as the baseline of ``benchmarks/bench_plumbing.py``
    (``timers`` is not supported: profiling uses the generated loop).

    ``advance.finish_step(k, slot, t0, H, k_start)`` (used by both loops) completes
    communication step ``k`` of the block that began at ``k_start`` after the FMU in
    ``slot`` returned ``fmi2Discard`` with ``fmi2Terminated`` at ``t_{k+1}``: it reads
    that FMU's outputs and steps the FMUs after it in the stepping order as usual
    (the master then samples row ``t_{k+1}``, also off the output grid). Returns ``k + 1``.

    ``loops`` (the components of each algebraic loop, ``simulation.algebraic_loops =
    "iterate"``): after all FMUs stepped to ``t_{k+1}``, ``advance.loop_solver``
    (:class:`~orchestrator.cosim.algebraic_loops.LoopSolver`, None without loops) iterates
    them on that row; the generated loop has no such sweeps.
    """
    if timers is not None:
        raise ValueError("profiling timers need the generated step loop")
    n_cols = ring.shape[1]
    flat = ring.reshape(-1)
    direct = ring is data
    linear = extrapolation == "linear"
    position = {id(s): i for i, s in enumerate(slots)}
    plan = []
    for i, s in enumerate(slots):
        # (input index, source already stepped this step (Gauss-Seidel), source column)
        feeds = [(j, algorithm == "gauss-seidel" and src < position[id(s)], col) for j, src, col in s.feeds
                 if j not in s.linear]
        # transformed connections (SSP LinearTransformation, unit conversion): (..., factor, offset)
        lin_feeds = [(j, algorithm == "gauss-seidel" and src < position[id(s)], col) + s.linear[j]
                     for j, src, col in s.feeds if j in s.linear]
        before = after = None
        if s.ports is not None:
            before, after = s.ports.bind(ring, text, stride, algorithm == "gauss-seidel", direct, _Stop)
            before = before if s.ports.inputs else None
            after = after if s.ports.outputs else None
        plan.append((i, s.inst, s.in_buf, ctypes.addressof(s.in_buf), ctypes.addressof(s.in_vr), len(s.in_names),
                     ctypes.addressof(s.out_vr), len(s.out_names), s.n_couple, s.col0 * ctypes.sizeof(c_double),
                     feeds, lin_feeds, before, after))
    base = ring.ctypes.data
    solver = None
    if loops:
        names = [s.name for s in slots]
        solver = LoopSolver(loop_groups(plan, loops, names), loops, loop_tolerance, loop_max_iterations, _Stop)

    def rows_of(k: int, k_start: int) -> tuple[int, int, int, int]:
        """(offset of t_{k+1}, t_k, t_{k-1} in ``flat``, the block's row offset c)."""
        if direct:  # block buffer: row k - k_start + 1 holds t_k
            c = 1 - k_start
            o0 = (k + c) * n_cols
            return o0 + n_cols, o0, o0 - n_cols, c
        return ((k + 1) % 3) * n_cols, (k % 3) * n_cols, ((k - 1) % 3) * n_cols, 0

    def set_inputs(buf, feeds, lin_feeds, o1, o0, om) -> None:
        for j, upstream, col in feeds:
            latest, previous = (o1, o0) if upstream else (o0, om)
            if linear:
                a = 0.5 if upstream else 1.5
                buf[j] = a * flat[latest + col] + (1.0 - a) * flat[previous + col]
            else:
                buf[j] = flat[latest + col]
        for j, upstream, col, factor, shift in lin_feeds:
            latest, previous = (o1, o0) if upstream else (o0, om)
            if linear:
                a = 0.5 if upstream else 1.5
                buf[j] = factor * (a * flat[latest + col] + (1.0 - a) * flat[previous + col]) + shift
            else:
                buf[j] = factor * flat[latest + col] + shift

    def step_slot(entry, k: int, t: float, H: float, o1: int, o0: int, om: int, c: int) -> None:
        """One FMU's inputs (Real and typed) and its ``fmi2DoStep`` from ``t_k``."""
        i, inst, buf, buf_addr, vr_in, n_in, _, _, _, _, feeds, lin_feeds, before, _ = entry
        set_inputs(buf, feeds, lin_feeds, o1, o0, om)
        if before is not None:
            before(k, c)
        if n_in:
            st = inst.set_real(inst.component, vr_in, n_in, buf_addr)
            if st > 1:
                raise _Stop(i, "fmi2SetReal", st, k)
        st = inst.do_step(inst.component, t, H, 1)
        if st > 1:
            raise _Stop(i, "fmi2DoStep", st, k)

    def read_slot(entry, k: int, n: int, a1: int, c: int) -> None:
        """The first ``n`` Real outputs of one FMU at ``t_{k+1}`` (and its typed outputs)."""
        i, inst, _, _, _, _, vr_out, _, _, offset, _, _, _, after = entry
        if n:
            st = inst.get_real(inst.component, vr_out, n, a1 + offset)
            if st > 1:
                raise _Stop(i, "fmi2GetReal", st, k)
        if after is not None:
            after(k, c)

    def advance(k_start: int, k_end: int, t0: float, H: float) -> int:
        r0 = k_start // stride + 1
        for k in range(k_start, k_end):
            t = t0 + k * H
            o1, o0, om, c = rows_of(k, k_start)
            sample = (k + 1) % stride == 0
            a1 = base + o1 * ctypes.sizeof(c_double)
            for entry in plan:
                step_slot(entry, k, t, H, o1, o0, om, c)
                read_slot(entry, k, entry[7] if (stride == 1 or sample) else entry[8], a1, c)  # all or coupling
            if solver is not None:
                solver.solve(flat[o1:o1 + n_cols], k, t + H)
            if not direct and sample:
                data[(k + 1) // stride - r0] = ring[(k + 1) % 3]
        return k_end

    def finish_step(k: int, first: int, t0: float, H: float, k_start: int) -> int:
        t = t0 + k * H
        o1, o0, om, c = rows_of(k, k_start)
        a1 = base + o1 * ctypes.sizeof(c_double)
        for entry in plan[first:]:
            if entry[0] > first:  # the FMUs after the one that ended: their usual step
                step_slot(entry, k, t, H, o1, o0, om, c)
            read_slot(entry, k, entry[7], a1, c)
        if solver is not None:
            solver.solve(flat[o1:o1 + n_cols], k, t + H)
        return k + 1

    advance.finish_step = finish_step
    advance.loop_solver = solver
    return advance
