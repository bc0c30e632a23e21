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
(:mod:`orchestrator.cosim.fmi_runtime`). ``fmi2GetReal`` writes straight into the
preallocated numpy result array (or, when not every step is sampled, into a
three-row ring buffer copied into the results on sampling steps), and the coupled
inputs are read from there: no per-step Python objects, no copies. The loop is
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
statement of that coupling only.

Stopping
--------
An FMU status worse than warning stops the run with an :class:`FmuStepError`
message (FMU, function, time, status, the FMU's log); Ctrl-C (SIGINT) is caught
between blocks of steps. Either way the samples recorded so far are returned with
``complete = False``. An FMU that ends the simulation itself (``fmi2Discard`` with
``fmi2Terminated`` after progress, :mod:`orchestrator.cosim.termination`) ends the
run normally: ``complete = True``, ``ended_by`` naming it.
"""

from __future__ import annotations

import ctypes
import math
import signal
import threading
import time
from ctypes import c_double
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import FmuStepError, InitializationError
from .fmi_runtime import FmuInstance, value_references
from .system import RecordedVariable, ResolvedSystem
from .termination import discard_status
from .values import TextStore, TypedPorts

#: stepping-loop implementations (see :func:`compile_step_loop`)
STEP_LOOPS = ("generated", "interpreted")
#: steps between checks for Ctrl-C and progress updates
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
        Why the run stopped early (FMU failure or interruption).
    interrupted : bool
        True if stopped by Ctrl-C.
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
    text: dict[str, np.ndarray] = field(default_factory=dict)
    ended_by: str | None = None

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
    step_loop : {"generated", "interpreted"}
        :func:`compile_step_loop` (default) or its plain-Python reference :func:`interpreted_step_loop`.
    """

    def __init__(self, system: ResolvedSystem, profile: bool = False, step_loop: str = "generated") -> None:
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
            wall_time_limit_s: float | None = None) -> RunOutcome:
        """Instantiate, initialise, step to the stop time and free the FMUs.

        Parameters
        ----------
        progress : callable(done_steps, total_steps), optional
            Called every :data:`BLOCK_STEPS` steps.
        handle_sigint : bool
            Catch Ctrl-C between blocks of steps (main thread only) and return
            the partial results instead of raising KeyboardInterrupt.
        wall_time_limit_s : float, optional
            Stop stepping (between blocks of steps) once the run has taken this
            much wall-clock time [s]; the outcome is then incomplete, with an error
            naming the limit and the time reached. None or 0: no limit.

        Returns
        -------
        RunOutcome
            Also when an FMU fails or the run is interrupted (``complete`` False).

        Raises
        ------
        FmuStepError, InitializationError
            If instantiation or initialisation fails (nothing to record yet).
        """
        wall0 = time.perf_counter()
        cpu0 = time.process_time()
        sim = self.settings
        n_steps = sim.n_steps
        stride = sim.output_stride
        n_rows = n_steps // stride + 2  # + 1: a last sample off the output grid when an FMU ends the run
        self._ended = None
        try:
            self._instantiate()
            initial_values = self._initialize()
            slots, columns, n_text = self._build_slots()
            n_cols = max(1, len(columns))
            data = np.full((n_rows, n_cols), np.nan)
            ring = data if stride == 1 else np.full((3, n_cols), np.nan)
            text = TextStore(n_rows, n_text)
            # row 0: every output at t0, after initialisation
            for s in slots:
                if s.out_names:
                    values = s.inst.get_reals(s.out_names, sim.start_s)
                    data[0, s.col0:s.col0 + len(values)] = values
                if s.ports is not None:
                    s.ports.read_initial(data[0], text, sim.start_s)
            if ring is not data:
                ring[:] = data[0]
            timers = np.zeros((len(slots), 3)) if self.profile else None
            make_loop = compile_step_loop if self.step_loop == "generated" else interpreted_step_loop
            advance = make_loop(slots, sim.algorithm, sim.extrapolation, stride, data, ring, timers, text=text)
            loop0 = time.perf_counter()
            loop_cpu0 = time.process_time()
            deadline = wall0 + wall_time_limit_s if wall_time_limit_s else math.inf
            k_done, error, interrupted = self._loop(advance, slots, data, n_steps, stride, progress, handle_sigint,
                                                    deadline, wall_time_limit_s)
            loop_time = time.perf_counter() - loop0
            loop_cpu = time.process_time() - loop_cpu0
        finally:
            self._close()
        rows = k_done // stride + 1
        times = sim.start_s + sim.step_s * stride * np.arange(rows, dtype=float)
        stopped_at = sim.start_s + k_done * sim.step_s
        if self._ended is not None and k_done % stride:  # the terminating FMU's last sample, off the grid
            times = np.append(times, stopped_at)
            rows += 1
        keys = [(c.component, c.variable) for c in columns]
        order = [keys.index((rv.component, rv.variable)) for rv in self.system.recorded]
        text_columns = {}
        for s in slots:
            if s.ports is not None:
                for name, typ, col in s.ports.outputs:
                    if typ == "String":
                        text_columns[f"{s.name}.{name}"] = text.rows[:rows, col].copy()
        return RunOutcome(
            time_s=times,
            values=np.ascontiguousarray(data[:rows][:, order]),
            columns=tuple(self.system.recorded),
            complete=error is None,
            steps=k_done,
            stopped_at_s=stopped_at,
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
            text={rv.column: text_columns[rv.column] for rv in self.system.recorded if rv.column in text_columns},
            ended_by=None if self._ended is None else self._ended[0],
        )

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
    def _instantiate(self) -> None:
        sim = self.settings
        sc = self.system.scenario
        for name in self.system.init_order:
            inst = FmuInstance(name, self.system.interfaces[name])
            self.instances[name] = inst
            inst.instantiate(sim.start_s, sim.stop_s)
            params = dict(sc.component(name).parameters)
            if params:
                inst.set_values(params, sim.start_s)
            inst.enter_initialization(sim.start_s)

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
                    if last.get(key) != v:
                        changed.append(key)
                    last[key] = v
                    values[dst.variable] = v
                self.instances[name].set_values(values, t0)
            if not changed:
                break
        else:
            raise InitializationError(
                f"initialisation did not reach a fixed point after {max_sweeps} sweeps; still changing: {', '.join(changed)}"
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
    def _loop(self, advance, slots, data, n_steps, stride, progress, handle_sigint, deadline=math.inf,
              wall_time_limit_s=None) -> tuple[int, str | None, bool]:
        """Step until the stop time, an FMU failure, Ctrl-C or the ``time.perf_counter()`` deadline.

        Returns (communication steps completed, error message or None, interrupted).
        """
        t0, H = self.settings.start_s, self.settings.step_s
        stop_flag = {"stop": False}
        previous_handler = None
        if handle_sigint and threading.current_thread() is threading.main_thread():
            def on_sigint(signum, frame):
                stop_flag["stop"] = True
                signal.signal(signal.SIGINT, signal.default_int_handler)  # a second Ctrl-C aborts at once

            previous_handler = signal.signal(signal.SIGINT, on_sigint)
        k = 0
        error = None
        interrupted = False
        try:
            while k < n_steps:
                if stop_flag["stop"]:
                    interrupted = True
                    error = f"interrupted by the user (Ctrl-C) at t = {t0 + k * H:.6g} s"
                    break
                k_end = min(n_steps, k + BLOCK_STEPS)
                try:
                    k = advance(k, k_end, t0, H)
                except _Stop as stop:
                    s = slots[stop.slot]
                    discard = discard_status(s.inst, stop.function, stop.status, t0 + stop.k * H,
                                             t0 + (stop.k + 1) * H)
                    if discard is not None and discard.ends_run:  # the FMU ended the simulation
                        try:
                            k = advance.finish_step(stop.k, stop.slot, t0, H) if discard.reached_step_end else stop.k
                        except _Stop as second:
                            stop, discard = second, None
                            s = slots[stop.slot]
                        else:
                            self._ended = (s.name, t0 + k * H)
                            break
                    s.inst.mark_failed(stop.status)
                    error = str(FmuStepError(s.name, stop.function, t0 + stop.k * H, stop.status, list(s.inst.log)))
                    if discard is not None:
                        error += discard.note()
                    k = stop.k
                    break
                if progress is not None:
                    progress(k, n_steps)
                if k < n_steps and time.perf_counter() > deadline:
                    error = f"wall-time limit of {wall_time_limit_s:g} s reached at t = {t0 + k * H:.6g} s"
                    break
        except KeyboardInterrupt:  # a second Ctrl-C, or no handler outside the main thread
            interrupted = True
            error = f"interrupted by the user (Ctrl-C) at t = {t0 + k * H:.6g} s"
        finally:
            if previous_handler is not None:
                signal.signal(signal.SIGINT, previous_handler)
        return k, error, error is not None and interrupted


def compile_step_loop(slots: list[_Slot], algorithm: str, extrapolation: str, stride: int,
                      data: np.ndarray, ring: np.ndarray, timers: np.ndarray | None = None,
                      text: TextStore | None = None) -> Callable:
    """Generate the stepping loop of one system, unrolled over its FMUs and couplings.

    Outputs at ``t_{k+1}`` are written by ``fmi2GetReal`` into row ``k + 1`` of
    ``ring`` (``ring is data`` when every step is sampled) or, with a three-row
    ring buffer, into row ``(k + 1) % 3``, which is copied to ``data`` on sampling
    steps. An input reads its source's column in the row of the sample it needs:
    ``k + 1`` for a source already stepped in this step (Gauss-Seidel), ``k``
    otherwise, and one row earlier for the second sample of ``linear``.

    Parameters
    ----------
    slots : list of _Slot
        Components in stepping order with their column blocks and feeds.
    algorithm : {"gauss-seidel", "jacobi"}
    extrapolation : {"hold", "linear"}
    stride : int
        Steps per sample.
    data : ndarray, shape (n_rows, n_cols)
        Sampled results; row 0 filled.
    ring : ndarray
        ``data`` itself (stride 1) or a (3, n_cols) ring buffer holding row 0.
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
        ``advance.finish_step(k, slot, t0, H) -> k + 1`` completes step ``k`` after the FMU
        in ``slot`` ended the simulation (see :func:`interpreted_step_loop`).

    Notes
    -----
    An FMU with Integer, Enumeration, Boolean or String ports (:mod:`orchestrator.cosim.values`)
    gets two more calls per step, ``before(k)`` ahead of its ``fmi2SetReal`` and
    ``after(k)`` behind its ``fmi2GetReal``; a system of Real variables only has none.
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

    def row_expr(offset: int) -> str:
        """Element offset of row k + offset."""
        if direct:
            return f"(k + {offset}) * {n_cols}" if offset >= 0 else f"max(k + {offset}, 0) * {n_cols}"
        return f"((k + {offset}) % 3) * {n_cols}"

    body = ["t = t0 + k * H", f"o1 = {row_expr(1)}", f"o0 = {row_expr(0)}", f"a1 = BASE + o1 * {dsize}"]
    if linear:
        body.append(f"om = {row_expr(-1)}")
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

        if typed_before:
            body.append(f"tb{i}(k)")
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
            body.append(f"ta{i}(k)")
    if not direct:
        body.append("if sample:")
        body.append(f"    data[(k + 1) // {stride}] = ring[(k + 1) % 3]")
    lines = ["def advance(k_start, k_end, t0, H):", "    for k in range(k_start, k_end):"]
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
                          text: TextStore | None = None) -> Callable:
    """The same stepping loop as :func:`compile_step_loop`, as plain Python over the slots (no generated code).

    It makes the same FMI calls with the same values in the same order, so its
    results are identical; it exists as the reference the generated loop is
    tested against and as the baseline of ``benchmarks/bench_plumbing.py``
    (``timers`` is not supported: profiling uses the generated loop).

    ``advance.finish_step(k, slot, t0, H)`` (used by both loops) completes
    communication step ``k`` after the FMU in ``slot`` returned ``fmi2Discard`` with
    ``fmi2Terminated`` at ``t_{k+1}``: it reads that FMU's outputs, steps the FMUs
    after it in the stepping order as usual and samples row ``t_{k+1}``, also off
    the output grid (the row after the last regular one). Returns ``k + 1``.
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

    def row(k: int) -> int:
        if direct:
            return max(k, 0) * n_cols
        return (k % 3) * n_cols

    def advance(k_start: int, k_end: int, t0: float, H: float) -> int:
        for k in range(k_start, k_end):
            t = t0 + k * H
            o1, o0, om = row(k + 1), row(k), row(k - 1)
            sample = (k + 1) % stride == 0
            a1 = base + o1 * ctypes.sizeof(c_double)
            for i, inst, buf, buf_addr, vr_in, n_in, vr_out, n_all, n_couple, offset, feeds, lin_feeds, before, \
                    after in plan:
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
                if before is not None:
                    before(k)
                if n_in:
                    st = inst.set_real(inst.component, vr_in, n_in, buf_addr)
                    if st > 1:
                        raise _Stop(i, "fmi2SetReal", st, k)
                st = inst.do_step(inst.component, t, H, 1)
                if st > 1:
                    raise _Stop(i, "fmi2DoStep", st, k)
                n = n_all if (stride == 1 or sample) else n_couple
                if n:
                    st = inst.get_real(inst.component, vr_out, n, a1 + offset)
                    if st > 1:
                        raise _Stop(i, "fmi2GetReal", st, k)
                if after is not None:
                    after(k)
            if not direct and sample:
                data[(k + 1) // stride] = ring[(k + 1) % 3]
        return k_end

    def finish_step(k: int, first: int, t0: float, H: float) -> int:
        t = t0 + k * H
        o1, o0, om = row(k + 1), row(k), row(k - 1)
        a1 = base + o1 * ctypes.sizeof(c_double)
        for i, inst, buf, buf_addr, vr_in, n_in, vr_out, n_all, n_couple, offset, feeds, lin_feeds, before, \
                after in plan[first:]:
            if i > first:  # the FMUs after the one that ended: their usual step
                for j, upstream, col, *transform in feeds + lin_feeds:
                    latest, previous = (o1, o0) if upstream else (o0, om)
                    if linear:
                        a = 0.5 if upstream else 1.5
                        value = a * flat[latest + col] + (1.0 - a) * flat[previous + col]
                    else:
                        value = flat[latest + col]
                    buf[j] = transform[0] * value + transform[1] if transform else value
                if before is not None:
                    before(k)
                if n_in:
                    st = inst.set_real(inst.component, vr_in, n_in, buf_addr)
                    if st > 1:
                        raise _Stop(i, "fmi2SetReal", st, k)
                st = inst.do_step(inst.component, t, H, 1)
                if st > 1:
                    raise _Stop(i, "fmi2DoStep", st, k)
            if n_all:
                st = inst.get_real(inst.component, vr_out, n_all, a1 + offset)
                if st > 1:
                    raise _Stop(i, "fmi2GetReal", st, k)
            if after is not None:
                after(k)
        if not direct:
            last_row = (k + 1) // stride + (1 if (k + 1) % stride else 0)
            data[last_row] = ring[(k + 1) % 3]
            if text is not None and text.rows.shape[1]:
                text.sample(last_row, k + 1, range(text.rows.shape[1]))
        return k + 1

    advance.finish_step = finish_step
    return advance
