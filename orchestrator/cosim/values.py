"""Integer, Enumeration, Boolean and String values in the stepping loop (everything but Real).

Real variables are exchanged by the stepping loop itself (one ``fmi2SetReal`` /
``fmi2GetReal`` per FMU and step, :mod:`orchestrator.cosim.stepping`); a system with
only Real variables never touches this module. The other FMI 2.0 types go through
one :class:`TypedPorts` per FMU that has such connections or recorded variables:

* Integer, Enumeration and Boolean outputs are read with ``fmi2GetInteger`` /
  ``fmi2GetBoolean`` into the same float row buffer as the Reals (every 32-bit
  integer is exact in a double; a Boolean is 0.0 or 1.0), so sampling, the ring
  buffer and the Gauss-Seidel/Jacobi choice of the sample an input receives work
  exactly as for Reals;
* String outputs are kept in a :class:`TextStore` (three ring rows and the sampled
  rows), since a double cannot hold them;
* inputs of these types always receive the held value (``linear`` extrapolation
  applies to Reals only: a discrete value has no slope).

Connections join variables of the same type only (an Enumeration only one of the
same declared type): :func:`type_mismatch` says why two variables cannot be joined.
"""

from __future__ import annotations

from ctypes import addressof, c_char_p, c_int
from typing import Callable, Mapping, Sequence

import numpy as np

from ..inputs.transformations import LinearTransformation
from .fmi_runtime import FmuInstance, value_references
from .fmu_interface import FmuVariable

#: the fmi2Get/Set function family of each non-Real type
FUNCTION_FAMILY = {"Integer": "Integer", "Enumeration": "Integer", "Boolean": "Boolean", "String": "String"}


def type_mismatch(source: FmuVariable, target: FmuVariable) -> str | None:
    """Why ``source`` cannot drive ``target`` (different FMI types or enumeration types), or None.

    An Integer and an Enumeration connect (both directions): FMI 2 exchanges an
    Enumeration as an Integer (``fmi2SetInteger``) and SSP 1.0 gives Enumeration
    the underlying type Integer.
    """
    if {source.type, target.type} == {"Integer", "Enumeration"}:
        return None
    if source.type != target.type:
        return f"{source.name} is {source.type}, {target.name} is {target.type}"
    if source.type == "Enumeration" and source.declared_type != target.declared_type:
        return (f"{source.name} is Enumeration {source.declared_type or '(no type)'}, "
                f"{target.name} is Enumeration {target.declared_type or '(no type)'}")
    return None


class TextStore:
    """String values of the run: a three-row ring (latest samples) and the sampled rows.

    Parameters
    ----------
    n_rows : int
        Sampled rows (as the numeric result array).
    n_columns : int
        String columns (outputs of type String, coupled or recorded).
    """

    def __init__(self, n_rows: int, n_columns: int) -> None:
        self.ring: list[list[str]] = [[""] * n_columns for _ in range(3)]
        self.rows = np.full((n_rows, n_columns), "", dtype=object)

    def sample(self, row: int, k_plus_1: int, columns: Sequence[int]) -> None:
        """Copy the ring row of step ``k + 1`` into sampled ``row`` for ``columns``."""
        ring = self.ring[k_plus_1 % 3]
        for c in columns:
            self.rows[row, c] = ring[c]


class TypedPorts:
    """The non-Real inputs and outputs of one FMU in the stepping loop.

    Parameters
    ----------
    slot : int
        Position of the FMU in the stepping order (reported with a failing status).
    inst : FmuInstance
    outputs : sequence of (name, type, column)
        Outputs read after every step; ``column`` is the column in the float row buffer
        (Integer, Enumeration, Boolean) or in the :class:`TextStore` (String).
    inputs : sequence of (name, type, source slot, source column[, table])
        Connected inputs with the column of the output that drives them and, for a
        mapping transformation on the connection, its int -> int table
        (:func:`numeric_transformation`).
    """

    def __init__(self, slot: int, inst: FmuInstance, outputs: Sequence[tuple[str, str, int]],
                 inputs: Sequence[tuple[str, str, int, int]]) -> None:
        self.slot = slot
        self.inst = inst
        self.outputs = list(outputs)
        self.inputs = [tuple(i) + (None,) * (5 - len(i)) for i in inputs]
        iface = inst.interface
        self._out_groups = []  # (getter, family, vr array, value buffer, columns)
        for family in ("Integer", "Boolean", "String"):
            members = [(n, col) for n, t, col in self.outputs if FUNCTION_FAMILY[t] == family]
            if members:
                vr = value_references(iface, [n for n, _ in members])
                buf = (c_char_p if family == "String" else c_int) * len(members)
                self._out_groups.append((inst.typed_get[family], family, vr, buf(), [col for _, col in members]))
        self._in_groups = []  # (setter, family, vr array, value buffer, [(index, source slot, source column)])
        for family in ("Integer", "Boolean", "String"):
            members = [(n, src, col, table) for n, t, src, col, table in self.inputs if FUNCTION_FAMILY[t] == family]
            if members:
                vr = value_references(iface, [m[0] for m in members])
                buf = (c_char_p if family == "String" else c_int) * len(members)
                feeds = [(j, src, col, table) for j, (_, src, col, table) in enumerate(members)]
                self._in_groups.append((inst.typed_set[family], family, vr, buf(), feeds))

    @property
    def string_columns(self) -> list[int]:
        """TextStore columns of this FMU's String outputs."""
        return [col for _, t, col in self.outputs if t == "String"]

    def bind(self, ring: np.ndarray, text: TextStore, stride: int, gauss_seidel: bool, direct: bool,
             stop: Callable[..., Exception]) -> tuple[Callable[[int], None], Callable[[int], None]]:
        """The loop's two calls for this FMU: ``before(k, c)`` (set inputs) and ``after(k, c)`` (read outputs).

        ``c`` is the row offset of the block buffer when every step is sampled (row
        ``k + c`` holds ``t_k``, :class:`orchestrator.cosim.stepping.plan.RowBuffers`); unused with the ring.

        Parameters
        ----------
        ring : ndarray
            The float row buffer (the master's block buffer when every step is sampled).
        text : TextStore
        stride : int
            Steps per sample.
        gauss_seidel : bool
            Inputs from FMUs stepped earlier in this step receive their new values.
        direct : bool
            ``ring`` is the block buffer (rows ``k + c``) rather than a three-row ring (rows ``k % 3``).
        stop : callable(slot, function, status, k) -> Exception
            Builds the exception raised on a status worse than fmi2Warning.
        """
        flat = ring.reshape(-1)
        n_cols = ring.shape[1]
        component = self.inst.component
        slot = self.slot
        string_columns = self.string_columns

        def row(k: int, c: int) -> int:
            return (k + c) * n_cols if direct else (k % 3) * n_cols

        in_plan = [(setter, family, addressof(vr), len(feeds), buf, addressof(buf),
                    [(j, gauss_seidel and src < slot, col, table) for j, src, col, table in feeds])
                   for setter, family, vr, buf, feeds in self._in_groups]
        out_plan = [(getter, family, addressof(vr), len(cols), buf, addressof(buf), cols)
                    for getter, family, vr, buf, cols in self._out_groups]

        def before(k: int, c: int = 0) -> None:
            o_new, o_now = row(k + 1, c), row(k, c)
            for setter, family, vr, n, buf, addr, feeds in in_plan:
                if family == "String":
                    for j, upstream, col, _ in feeds:
                        buf[j] = text.ring[(k + 1) % 3 if upstream else k % 3][col].encode("utf-8")
                else:
                    for j, upstream, col, table in feeds:
                        value = int(flat[(o_new if upstream else o_now) + col])
                        buf[j] = value if table is None else table.get(value, value)
                st = setter(component, vr, n, addr)
                if st > 1:
                    raise stop(slot, f"fmi2Set{family}", st, k)

        def after(k: int, c: int = 0) -> None:
            o_new = row(k + 1, c)
            for getter, family, vr, n, buf, addr, cols in out_plan:
                st = getter(component, vr, n, addr)
                if st > 1:
                    raise stop(slot, f"fmi2Get{family}", st, k)
                if family == "String":
                    latest = text.ring[(k + 1) % 3]
                    for i, col in enumerate(cols):
                        value = buf[i]
                        latest[col] = value.decode("utf-8", "replace") if value is not None else ""
                elif family == "Boolean":
                    for i, col in enumerate(cols):
                        flat[o_new + col] = 1.0 if buf[i] else 0.0
                else:
                    for i, col in enumerate(cols):
                        flat[o_new + col] = buf[i]
            if string_columns and (k + 1) % stride == 0:
                text.sample((k + 1) // stride, k + 1, string_columns)

        return before, after

    def read_initial(self, row0: np.ndarray, text: TextStore, time_s: float) -> None:
        """Outputs at the start time (after initialisation) into result row 0 and the text ring row 0."""
        names = [n for n, _, _ in self.outputs]
        values = self.inst.get_values(names, time_s)
        for (name, typ, col), value in zip(self.outputs, values):
            if typ == "String":
                text.ring[0][col] = value
                text.rows[0, col] = value
            else:
                row0[col] = float(value)


def transformation_problem(transformation, source: FmuVariable, target: FmuVariable,
                           source_types: Mapping[str, Mapping[str, int]],
                           target_types: Mapping[str, Mapping[str, int]]) -> str | None:
    """Why a connection's transformation does not fit its variables' type, or None.

    ``source_types`` and ``target_types`` are the two FMUs' Enumeration types
    (:attr:`FmuInterface.enumerations`), for an Enumeration mapping's item names.
    """
    if transformation is None:
        return None
    if isinstance(transformation, LinearTransformation):
        return None if target.type == "Real" else f"a Real connection for a linear transformation; {target.name} is {target.type}"
    kinds = {"Boolean": ("Boolean",), "Integer": ("Integer", "Enumeration"), "Enumeration": ("Enumeration",)}
    if target.type not in kinds[transformation.kind]:
        return (f"a {' or '.join(kinds[transformation.kind])} connection for a {transformation.kind} mapping; "
                f"{target.name} is {target.type}")
    if transformation.kind == "Enumeration":
        for var, types, side in ((source, source_types, 0), (target, target_types, 1)):
            items = types.get(var.declared_type, {})
            for entry in transformation.entries:
                if entry[side] not in items:
                    return (f"item names of {var.declared_type or 'the enumeration'} of {var.name} "
                            f"({', '.join(items) or 'none'}); {entry[side]!r} is not one")
    return None


def numeric_transformation(transformation, source: FmuVariable, target: FmuVariable,
                           source_types: Mapping[str, Mapping[str, int]],
                           target_types: Mapping[str, Mapping[str, int]]):
    """What the loop applies: a :class:`LinearTransformation`, an int -> int table (Booleans 0/1), or None."""
    if transformation is None or isinstance(transformation, LinearTransformation):
        return transformation
    if transformation.kind == "Enumeration":
        src = source_types[source.declared_type]
        dst = target_types[target.declared_type]
        return {src[a]: dst[b] for a, b in transformation.entries}
    return {int(a): int(b) for a, b in transformation.entries}
