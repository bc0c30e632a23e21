"""The stepping plan: what one communication step does for each FMU, named, built once per run.

A :class:`StepPlan` lists the FMUs in stepping order. For each, a :class:`FmuStep`
says which Real inputs it receives (each a :class:`Feed`: the row-buffer column of
the output that drives it, whether that source already stepped in this step, and
the connection's linear transformation), which Real outputs it returns (the
coupling outputs first, read every step, then its other recorded variables, read
on sampling steps) and where they go in the row buffer, with the value-reference
arrays its ``fmi2SetReal``/``fmi2GetReal`` calls take. Every FMU's Real inputs live
in one float buffer, :attr:`StepPlan.input_values`. Both executors run this plan:
:mod:`~orchestrator.cosim.stepping.python_loop` reads it as objects,
:mod:`~orchestrator.cosim.stepping.compiled_loop` as arrays of the same numbers.

:class:`RowBuffers` is where the outputs go (the block buffer, and a three-row
ring when not every step is sampled) and which rows a step reads and writes.
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from ..fmi_runtime import FmuInstance, value_references
from ..resolved import RecordedVariable, ResolvedSystem
from ..values import TextStore, TypedPorts

#: bytes of one float64 value in the row and input buffers
VALUE_BYTES = ctypes.sizeof(ctypes.c_double)


class StepFailed(Exception):
    """A raw FMI call of the stepping loop returned a status worse than ``fmi2Warning``.

    Parameters
    ----------
    slot : int
        Position of the FMU in the stepping order.
    function : str
        The FMI function (``"fmi2DoStep"``, ...).
    status : int
        The status it returned.
    k : int
        The communication step (from ``t_k`` to ``t_{k+1}``).
    """

    def __init__(self, slot: int, function: str, status: int, k: int) -> None:
        super().__init__(slot, function, status, k)
        self.slot, self.function, self.status, self.k = slot, function, status, k


@dataclass(frozen=True)
class Feed:
    """One coupled Real input of an FMU.

    Attributes
    ----------
    input : int
        Index of the input in :attr:`StepPlan.input_values`.
    column : int
        Row-buffer column of the output that drives it.
    source : int
        Slot of the FMU that owns that output.
    upstream : bool
        The source steps before the receiver in a Gauss-Seidel step: the input
        receives the source's new value (at ``t_{k+1}``), else the value at ``t_k``.
    transformed : bool
        The connection has a linear transformation (SSP ``LinearTransformation``, a
        unit conversion): the input receives ``factor * value + offset``.
    factor, offset : float
    """

    input: int
    column: int
    source: int
    upstream: bool
    transformed: bool = False
    factor: float = 1.0
    offset: float = 0.0


@dataclass(eq=False)
class FmuStep:
    """What one communication step does for one FMU: set its inputs, ``fmi2DoStep``, read its outputs.

    Attributes
    ----------
    slot : int
        Position in the stepping order.
    instance : FmuInstance
        The instantiated FMU (its raw FMI functions and component handle).
    inputs : tuple of str
        Coupled Real inputs, set in one ``fmi2SetReal`` from
        ``input_values[first_input:first_input + len(inputs)]``.
    outputs : tuple of str
        Real outputs read in one ``fmi2GetReal`` into consecutive row-buffer columns
        from ``column``: the first ``n_coupling`` every step (they drive inputs), all
        on sampling steps.
    n_coupling : int
    column : int
        Row-buffer column of ``outputs[0]``.
    feeds : tuple of Feed
        Where each input's value comes from, in the order of ``inputs``.
    first_input : int
        Index of the first input in :attr:`StepPlan.input_values`.
    input_vrs, output_vrs : ctypes arrays of fmi2ValueReference
    ports : TypedPorts or None
        Integer, Enumeration, Boolean and String inputs and outputs (None: Real only).
    n_inputs, n_outputs : int
        ``len(inputs)``, ``len(outputs)``.
    input_address, input_vr_address, output_vr_address, output_offset : int
        The addresses the raw FMI calls take (``output_offset``: byte offset of
        ``column`` in a row).
    """

    slot: int
    instance: FmuInstance
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    n_coupling: int
    column: int
    feeds: tuple[Feed, ...]
    first_input: int
    input_vrs: ctypes.Array
    output_vrs: ctypes.Array
    ports: TypedPorts | None = None
    input_address: int = 0
    n_inputs: int = field(init=False)
    n_outputs: int = field(init=False)
    input_vr_address: int = field(init=False)
    output_vr_address: int = field(init=False)
    output_offset: int = field(init=False)

    def __post_init__(self) -> None:
        self.n_inputs, self.n_outputs = len(self.inputs), len(self.outputs)
        self.input_vr_address = ctypes.addressof(self.input_vrs)
        self.output_vr_address = ctypes.addressof(self.output_vrs)
        self.output_offset = self.column * VALUE_BYTES

    @property
    def name(self) -> str:
        """The component's name."""
        return self.instance.name


@dataclass(eq=False)
class StepPlan:
    """The whole system's step: its FMUs in stepping order and the layout of its row buffer.

    Attributes
    ----------
    fmus : tuple of FmuStep
        In stepping order.
    columns : tuple of RecordedVariable
        The row buffer's columns: each FMU's Real outputs as one block, in stepping
        order, then the Integer, Enumeration, Boolean and String ones (a String's
        column stays NaN; its values are in the :class:`~orchestrator.cosim.values.TextStore`).
    input_values : ndarray, shape (n_inputs,)
        Every FMU's coupled Real inputs (at least one element).
    recorded_columns : ndarray of int
        Row-buffer column of each recorded variable, in ``system.recorded`` order.
    text_columns : mapping of int -> int
        Recorded column -> TextStore column, for the recorded String variables.
    n_text : int
        TextStore columns (String outputs, coupled or recorded).
    algorithm : {"gauss-seidel", "jacobi"}
    extrapolation : {"hold", "linear"}
    stride : int
        Communication steps per sample.
    """

    fmus: tuple[FmuStep, ...]
    columns: tuple[RecordedVariable, ...]
    input_values: np.ndarray
    recorded_columns: np.ndarray
    text_columns: Mapping[int, int]
    n_text: int
    algorithm: str
    extrapolation: str
    stride: int

    @property
    def n_columns(self) -> int:
        """Columns of the row buffer (at least one)."""
        return max(1, len(self.columns))

    @property
    def linear(self) -> bool:
        """Inputs receive the linearly extrapolated value (else the held one)."""
        return self.extrapolation == "linear"

    def fmus_of(self, components) -> list[FmuStep]:
        """The steps of the named components, in stepping order."""
        names = set(components)
        return [f for f in self.fmus if f.name in names]


def build_plan(system: ResolvedSystem, instances: Mapping[str, FmuInstance]) -> StepPlan:
    """The plan of ``system`` over its instantiated FMUs (in ``system.order``).

    Real outputs that drive an input come first in their FMU's block (read every
    step), then the FMU's other recorded Real variables (read on sampling steps);
    the other types follow all Real blocks (:mod:`orchestrator.cosim.values`).
    """
    sim = system.scenario.simulation
    connections = system.scenario.connections
    names = list(system.order)
    slot_of = {name: i for i, name in enumerate(names)}

    def is_real(component: str, variable: str) -> bool:
        return system.interfaces[component].variables[variable].type == "Real"

    # the outputs each FMU returns: coupled ones first, then the recorded ones
    real_out: dict[str, list[str]] = {name: [] for name in names}
    typed_out: dict[str, list[str]] = {name: [] for name in names}
    for con in connections:
        src = con.source
        out = real_out[src.component] if is_real(src.component, src.variable) else typed_out[src.component]
        if src.variable not in out:
            out.append(src.variable)
    n_coupling = {name: len(real_out[name]) for name in names}
    for rv in system.recorded:
        out = real_out[rv.component] if is_real(rv.component, rv.variable) else typed_out[rv.component]
        if rv.variable not in out and rv.variable not in real_out[rv.component]:
            out.append(rv.variable)

    # the row buffer: every FMU's block of Real outputs, then the other types
    columns: list[RecordedVariable] = []
    first_column: dict[str, int] = {}
    for name in names:
        first_column[name] = len(columns)
        variables = system.interfaces[name].variables
        columns += [RecordedVariable(name, v, variables[v].value_reference, variables[v].unit) for v in real_out[name]]
    typed_column: dict[tuple[str, str], int] = {}  # float column, or TextStore column for a String
    typed_outputs: dict[str, list[tuple[str, str, int]]] = {name: [] for name in names}
    n_text = 0
    for name in names:
        for v in typed_out[name]:
            var = system.interfaces[name].variables[v]
            columns.append(RecordedVariable(name, v, var.value_reference, var.unit, var.type))
            if var.type == "String":
                col, n_text = n_text, n_text + 1
            else:
                col = len(columns) - 1
            typed_column[(name, v)] = col
            typed_outputs[name].append((v, var.type, col))

    def column_of(component: str, variable: str) -> int:
        return first_column[component] + real_out[component].index(variable)

    # the inputs each FMU receives, with the feeds that drive them
    gauss_seidel = sim.algorithm == "gauss-seidel"
    incoming = {name: [c for c in connections if c.target.component == name and is_real(name, c.target.variable)]
                for name in names}
    n_inputs = sum(len(cons) for cons in incoming.values())
    input_values = np.zeros(max(1, n_inputs))
    fmus = []
    first_input = 0
    for i, name in enumerate(names):
        inst = instances[name]
        feeds = []
        for j, con in enumerate(incoming[name]):
            source = slot_of[con.source.component]
            transform = system.loop_transformation(con)
            feeds.append(Feed(first_input + j, column_of(con.source.component, con.source.variable), source,
                              gauss_seidel and source < i, transform is not None,
                              *((transform.factor, transform.offset) if transform is not None else ())))
        typed_in = [(con.target.variable, system.variable(con.target).type, slot_of[con.source.component],
                     typed_column[(con.source.component, con.source.variable)], system.loop_transformation(con))
                    for con in connections if con.target.component == name and not is_real(name, con.target.variable)]
        inputs = tuple(c.target.variable for c in incoming[name])
        fmus.append(FmuStep(
            slot=i, instance=inst, inputs=inputs, outputs=tuple(real_out[name]), n_coupling=n_coupling[name],
            column=first_column[name], feeds=tuple(feeds), first_input=first_input,
            input_vrs=value_references(inst.interface, inputs),
            output_vrs=value_references(inst.interface, real_out[name]),
            ports=TypedPorts(i, inst, typed_outputs[name], typed_in) if typed_outputs[name] or typed_in else None,
            input_address=input_values.ctypes.data + first_input * VALUE_BYTES,
        ))
        first_input += len(inputs)

    keys = [(c.component, c.variable) for c in columns]
    recorded_columns = np.array([keys.index((rv.component, rv.variable)) for rv in system.recorded], dtype=np.intp)
    text_columns = {j: typed_column[(rv.component, rv.variable)] for j, rv in enumerate(system.recorded)
                    if rv.type == "String"}
    return StepPlan(tuple(fmus), tuple(columns), input_values, recorded_columns, text_columns, n_text,
                    sim.algorithm, sim.extrapolation, sim.output_stride)


@dataclass(eq=False)
class RowBuffers:
    """The rows the stepping loop reads its inputs from and writes its outputs to.

    With every step sampled (``stride`` 1) the loop writes straight into the block
    buffer: row ``k - k_start + 1`` holds the outputs at ``t_k``, so rows 0 and 1
    hold ``t_{k_start - 1}`` and ``t_{k_start}`` when a block starts (:meth:`rewind`
    carries them over; both are the initial row before the first block) and step
    ``k`` writes ``t_{k+1}`` into row ``k - k_start + 2``. Otherwise the outputs go
    to row ``(k + 1) % 3`` of a three-row ring, copied into the block's sample row
    ``(k + 1) // stride - (k_start // stride + 1)`` on sampling steps.

    Attributes
    ----------
    block : ndarray, shape (n_rows, n_columns)
        The sample rows of one block of steps.
    ring : ndarray
        ``block`` itself (stride 1) or the (3, n_columns) ring.
    stride : int
        Steps per sample.
    """

    block: np.ndarray
    ring: np.ndarray
    stride: int
    flat: np.ndarray = field(init=False)
    address: int = field(init=False)

    def __post_init__(self) -> None:
        self.flat = self.ring.reshape(-1)  # a view: the loops index rows by offset
        self.address = self.ring.ctypes.data

    @classmethod
    def allocate(cls, n_columns: int, stride: int, block_steps: int) -> "RowBuffers":
        """Buffers for blocks of ``block_steps`` steps, filled with NaN."""
        if stride == 1:  # rows k_start - 1 and k_start of each block, then one row per step
            block = np.full((block_steps + 2, n_columns), np.nan)
            return cls(block, block, 1)
        block = np.full((block_steps // stride + 2, n_columns), np.nan)
        return cls(block, np.full((3, n_columns), np.nan), stride)

    @property
    def direct(self) -> bool:
        """Every step is sampled: the loop writes into the block buffer itself."""
        return self.ring is self.block

    @property
    def n_columns(self) -> int:
        return self.ring.shape[1]

    def offsets(self, k: int, k_start: int) -> tuple[int, int, int, int]:
        """``(new, now, before, c)``: offsets in :attr:`flat` of the rows of ``t_{k+1}``, ``t_k`` and
        ``t_{k-1}`` in the block that began at ``k_start``, and the block's row offset ``c`` (row
        ``k + c`` holds ``t_k``; 0 with the ring)."""
        n = self.ring.shape[1]
        if self.ring is self.block:
            c = 1 - k_start
            now = (k + c) * n
            return now + n, now, now - n, c
        return ((k + 1) % 3) * n, (k % 3) * n, ((k - 1) % 3) * n, 0

    def sample(self, k: int, k_start: int) -> None:
        """Copy the ring row of ``t_{k+1}`` into the block's sample row (a sampling step, ring only)."""
        self.block[(k + 1) // self.stride - (k_start // self.stride + 1)] = self.ring[(k + 1) % 3]

    def start(self, first: np.ndarray) -> None:
        """Every row holds the outputs at the start time (before the first block)."""
        self.ring[:] = first

    def finished(self, k_start: int, k: int, ended: bool, text: TextStore) -> tuple[np.ndarray, bool]:
        """The block's finished sample rows (``t_{k_start + 1}`` ... ``t_k``) after steps up to ``k``.

        ``ended``: an FMU ended the run at ``t_k``; its last sample is kept also off the
        output grid. Returns ``(rows, off_grid)``, ``off_grid`` True when the last row is
        such a sample (at ``t_k`` rather than on the grid).
        """
        if self.ring is self.block:
            return self.block[2:k - k_start + 2], False
        stride = self.stride
        n_done = k // stride - k_start // stride
        if ended and k % stride:  # the terminating FMU's last sample, off the grid
            self.block[n_done] = self.ring[k % 3]
            text.sample(k // stride + 1, k, range(text.rows.shape[1]))
            return self.block[:n_done + 1], True
        if ended and k > k_start:  # a finished last step on the grid
            self.block[n_done - 1] = self.ring[k % 3]
        return self.block[:n_done], False

    def rewind(self, k_start: int, k: int) -> None:
        """Start the next block at step ``k`` (the rows of ``t_{k-1}`` and ``t_k`` go first)."""
        if self.ring is self.block:
            self.block[0:2] = self.block[k - k_start:k - k_start + 2]
