"""Base class of the dtcosim FMU slaves: FMI variables <-> component, errors, state.

A slave subclass declares its variables (:meth:`DtcosimSlave.build_interface`)
from the model its FMU records (``resources/dtcosim.json``, :mod:`.record`: the
parameter set the build was made from, read at instantiation) and implements five small hooks that talk to a ``components`` object:
``_configure`` (build it from the parameter values), ``_initialize`` (initial
state from inputs at the start time), ``_step``, ``_refresh`` (write one group
of outputs) and ``_component_state`` / ``_restore_component_state``.

Value storage
-------------
All variable values live in one list indexed by value reference, so
``get_real``/``set_real`` are list look-ups (the FMI round trip is on the hot
path of every communication step). Outputs are grouped; a group is computed
from the component only when one of its variables is read after a step.

How errors reach the host (pythonfmu 0.7 C wrapper)
----------------------------------------------------
* Messages queued with :meth:`log` are forwarded to the FMI logger after the
  call returns, but only when the host instantiated the FMU with
  ``loggingOn = fmi2True`` (or called ``fmi2SetDebugLogging``). Errors are
  therefore also echoed to ``sys.stderr`` (see :attr:`echo_errors_to_stderr`).
* ``do_step`` returning ``False`` gives ``fmi2Discard``: used for solver
  failures, arithmetic failures of a step (division by zero, overflow, a
  singular matrix: :func:`plain_reason`, never the Python exception's text),
  bad inputs and a communication point or step that is not a finite number
  (a step must also be > 0); the component state is left at the last
  communication point.
* A Python exception becomes ``fmi2Error`` in dtcosim's binary
  (``fmus/native/dtcosim_fmi2.c``), and ``fmi2Fatal`` with its text lost ("unknown
  error") in pythonfmu 0.7's C++ wrapper (still the win64 binary), so the message
  is always logged first (:meth:`_fail`). pythonfmu's wrapper also releases its
  references to the instance, the class and the log queue when the exception
  reaches it and again in ``fmi2FreeInstance``; that double release crashed
  the host after a few failed instances. :func:`_balance_wrapper_release` adds
  the one reference that wrapper takes back, only under that wrapper (it passes a
  ``logger`` keyword, dtcosim's binary does not).
"""

from __future__ import annotations

import ctypes
import json
import math
import sys
from abc import abstractmethod
from contextlib import contextmanager
from functools import partial
from typing import Any, Hashable, Iterable, Iterator, Mapping

from pythonfmu import (
    Boolean,
    DefaultExperiment,
    Fmi2Causality,
    Fmi2Initial,
    Fmi2Slave,
    Fmi2Variability,
    Integer,
    Real,
)
from pythonfmu.enums import Fmi2Status

from components import __version__ as COMPONENTS_VERSION
from components.errors import DtcosimError, ParameterError

from .interface import BOOLEAN, INPUT, INTEGER, OUTPUT, PARAMETER, REAL, Value, Variable
from .record import START_VALUES_KEY, FmuRecordError, read_fmu_record
from .shutdown import register_state_release

#: Life-cycle phases of an instance.
INSTANTIATED, INITIALIZATION, STEPPING, TERMINATED = "instantiated", "initialization", "stepping", "terminated"

#: Version of the dict returned by ``_get_fmu_state``.
STATE_FORMAT = 1

_PYTHONFMU_TYPES = {REAL: Real, INTEGER: Integer, BOOLEAN: Boolean}
_INF = math.inf


@contextmanager
def fmu_parameter_names(names: Mapping[str, str]) -> Iterator[None]:
    """Re-raise a component's :class:`ParameterError` under the FMU variable's name.

    Parameters
    ----------
    names : mapping of str to str
        Component parameter name (as in ``ParameterError.name``) -> FMU variable name.
    """
    try:
        yield
    except ParameterError as exc:
        fmu_name = names.get(exc.name)
        if fmu_name is None:
            raise
        raise ParameterError(fmu_name, exc.value, exc.expected, exc.bounds) from exc


#: exception types that are arithmetic failures of the model (solver discard while stepping)
_ARITHMETIC = (ArithmeticError,)


def is_arithmetic_failure(exc: BaseException) -> bool:
    """Division by zero, overflow, a floating-point error or a singular matrix (numpy's LinAlgError)."""
    return isinstance(exc, _ARITHMETIC) or type(exc).__name__ == "LinAlgError"


def plain_reason(exc: BaseException) -> str:
    """What went wrong, in words a user of the FMU can act on (no Python exception text for model failures)."""
    if isinstance(exc, DtcosimError):
        return str(exc)
    if type(exc).__name__ == "LinAlgError":
        return "the model's equations have a singular matrix with these parameter and input values"
    if isinstance(exc, ZeroDivisionError):
        return "a division by zero in the model with these parameter and input values"
    if isinstance(exc, (OverflowError, FloatingPointError)):
        return "a number in the model grew beyond the floating-point range with these parameter and input values"
    if isinstance(exc, MemoryError):
        return "not enough memory for the model with these parameter values"
    return f"{type(exc).__name__}: {exc}"  # a defect, not a user's input: the text helps to find it


class FmuError(Exception):
    """Raised to the pythonfmu wrapper (the host sees ``fmi2Fatal``); the message was logged before."""


def _balance_wrapper_release(instance: "DtcosimSlave") -> None:
    """Add one reference to each object the pythonfmu wrapper releases twice after an exception.

    pythonfmu 0.7's ``handle_py_exception`` releases its references to the
    instance, its class and the log queue, and ``fmi2FreeInstance`` releases
    them again. Without this extra reference the objects are freed while
    still referenced and the host crashes (reproduced: a segmentation fault
    after three failed instances).
    """
    incref = ctypes.pythonapi.Py_IncRef
    incref.argtypes = [ctypes.py_object]
    incref.restype = None
    for obj in (instance, type(instance), instance.log_queue):
        incref(obj)


class DtcosimSlave(Fmi2Slave):
    """Common FMI machinery of the dtcosim slaves (not an FMU by itself).

    Class attributes
    ----------------
    build_id : str
        Hash of the code the FMU was built from (set by the build).
    echo_errors_to_stderr : bool
        Also write error messages to ``sys.stderr`` (the wrapper drops logger
        messages unless the host enabled logging).
    eager_output_groups : frozenset
        Output groups refreshed at the end of every step (those a master reads
        every step); the other groups are computed when first read.
    """

    author = "dtcosim contributors"
    license = "MIT"
    copyright = "dtcosim contributors, MIT licence"
    version = COMPONENTS_VERSION
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=60.0, step_size=1.0e-3)
    build_id = "source"
    echo_errors_to_stderr = True
    eager_output_groups: frozenset = frozenset()

    _interface_cache: dict[tuple[type, str], tuple[Variable, ...]] = {}

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        #: created by pythonfmu's C++ wrapper (the win64 binary, or a build without a C compiler), which passes
        #: its logger; dtcosim's own binary (fmus/native/dtcosim_fmi2.c) passes none and needs no work-arounds
        self._pythonfmu_wrapper = "logger" in kwargs
        if self._pythonfmu_wrapper:
            register_state_release(self.resources)  # pythonfmu's exit-time use-after-free, see .shutdown
        #: the parameter set of this FMU's record (structure and defaults)
        record = read_fmu_record(self.resources)
        self.model: dict[str, Any] = record["model"]
        variables = self.interface(self.model)
        self.variables: tuple[Variable, ...] = variables
        self.vr: dict[str, int] = {v.name: i for i, v in enumerate(variables)}
        self._values: list[Value] = [0.0 if v.start is None else v.start for v in variables]
        self._apply_start_values(record.get(START_VALUES_KEY, {}))
        self._kind = [(v.type, v.causality) for v in variables]
        self._real_vrs = frozenset(i for i, v in enumerate(variables) if v.type == REAL)
        self._integer_vrs = frozenset(i for i, v in enumerate(variables) if v.type == INTEGER)
        self._boolean_vrs = frozenset(i for i, v in enumerate(variables) if v.type == BOOLEAN)
        self._parameter_vrs = tuple(i for i, v in enumerate(variables) if v.causality == PARAMETER)
        self._real_input_vrs = frozenset(i for i, v in enumerate(variables) if v.type == REAL and v.causality == INPUT)
        self._group_of: dict[int, Hashable] = {}
        for i, v in enumerate(variables):
            if v.causality == OUTPUT:
                self._group_of[i] = self.output_group(v.name)
        self._all_groups = frozenset(self._group_of.values())
        self._eager_groups = tuple(g for g in self._all_groups if g in self.eager_output_groups)
        self._lazy_groups = self._all_groups.difference(self._eager_groups)
        self._stale: set[Hashable] = set(self._all_groups)
        self._phase = INSTANTIATED
        self._start_time = 0.0
        self._time = 0.0
        self._params_dirty = True  # component must be (re)built from the parameter values
        self._initial_dirty = True  # initial state must be recomputed from inputs/parameters
        self._configured_params: tuple | None = None
        for i, v in enumerate(variables):
            self._register(i, v)

    # ------------------------------------------------------------------ interface
    @classmethod
    def interface(cls, model: Mapping[str, Any]) -> tuple[Variable, ...]:
        """The FMU's variables in value-reference order for the record's ``model`` (cached)."""
        key = (cls, json.dumps(model, sort_keys=True))
        if key not in DtcosimSlave._interface_cache:
            DtcosimSlave._interface_cache[key] = tuple(cls.build_interface(model))
        return DtcosimSlave._interface_cache[key]

    @classmethod
    @abstractmethod
    def build_interface(cls, model: Mapping[str, Any]) -> Iterable[Variable]:
        """Declare the variables of the record's ``model`` (called once per class and model)."""

    def output_group(self, name: str) -> Hashable:
        """Group key of an output: outputs of one group are refreshed together."""
        return name

    def _register(self, vr: int, var: Variable) -> None:
        kwargs: dict[str, Any] = dict(
            causality=Fmi2Causality[var.causality],
            variability=Fmi2Variability[var.variability],
            description=var.full_description,
            getter=partial(self._values.__getitem__, vr),
        )
        if var.causality == OUTPUT:
            kwargs["initial"] = Fmi2Initial.calculated
        else:
            kwargs["setter"] = partial(self._values.__setitem__, vr)
            if var.causality == PARAMETER:
                kwargs["initial"] = Fmi2Initial.exact
        self.register_variable(_PYTHONFMU_TYPES[var.type](var.name, **kwargs), nested=False)

    def _apply_start_values(self, start_values: Mapping[str, Any]) -> None:
        """The record's ``start_values`` (a copy written by :mod:`fmus.start_values`) over the model's defaults.

        Raises
        ------
        FmuRecordError
            A name that is not a parameter or input of this FMU, or a value of another type.
        """
        for name, value in start_values.items():
            vr = self.vr.get(name)
            if vr is None or self.variables[vr].causality not in (PARAMETER, INPUT):
                raise FmuRecordError(f"resources record {START_VALUES_KEY}: {name!r} is not a parameter or input of "
                                  f"this FMU")
            fmi_type = self.variables[vr].type
            wrong = (isinstance(value, bool) != (fmi_type == BOOLEAN)
                     or (fmi_type == REAL and not isinstance(value, (int, float)))
                     or (fmi_type == INTEGER and not isinstance(value, int)))
            if wrong:
                raise FmuRecordError(f"resources record {START_VALUES_KEY}: {name} = {value!r} is not a {fmi_type} value")
            self._values[vr] = float(value) if fmi_type == REAL else value

    def value(self, name: str) -> Value:
        """Current value of a variable by name."""
        return self._values[self.vr[name]]

    def parameter_values(self) -> dict[str, Value]:
        """Current values of all parameters by name."""
        return {self.variables[i].name: self._values[i] for i in self._parameter_vrs}

    # ---------------------------------------------------------------- component hooks
    @abstractmethod
    def _configure(self) -> None:
        """Build the component(s) from the parameter values; raise ParameterError naming the FMU variable."""

    @abstractmethod
    def _initialize(self, start_time: float) -> None:
        """Put the component(s) into their initial state from the current inputs."""

    @abstractmethod
    def _step(self, time: float, step_size: float) -> None:
        """Advance the component(s); raise a DtcosimError and leave the state unchanged on failure."""

    @abstractmethod
    def _refresh(self, group: Hashable) -> None:
        """Write the outputs of ``group`` into ``self._values`` from the component(s)."""

    @abstractmethod
    def _component_state(self) -> Any:
        """JSON-serialisable complete state of the configured component(s)."""

    @abstractmethod
    def _restore_component_state(self, state: Any) -> None:
        """Restore a state from :meth:`_component_state` (component(s) already configured)."""

    # ---------------------------------------------------------------- errors
    def _report(self, message: str, status: Fmi2Status = Fmi2Status.error) -> None:
        """Log a message through the FMI logger (and echo errors to stderr)."""
        self.log(message, status)
        if status >= Fmi2Status.error and self.echo_errors_to_stderr:
            print(f"[{type(self).__name__} {self.instance_name!r}] {message}", file=sys.stderr, flush=True)

    def _fail(self, context: str, exc: BaseException) -> None:
        """Log ``exc`` (:func:`plain_reason`) and raise it to the binary (the host gets ``fmi2Error``;
        ``fmi2Fatal`` from pythonfmu's wrapper)."""
        message = f"{context}: {plain_reason(exc)}"
        self._report(message, Fmi2Status.error)
        if self._pythonfmu_wrapper:
            _balance_wrapper_release(self)
        raise FmuError(message) from None

    # ---------------------------------------------------------------- life cycle
    def setup_experiment(self, start_time: float, stop_time: float | None = None, tolerance: float | None = None) -> None:
        """Record the start time [s]."""
        self._start_time = float(start_time)
        self._time = self._start_time
        self._initial_dirty = True
        self._stale = set(self._all_groups)

    def enter_initialization_mode(self) -> None:
        """Enter initialisation mode: outputs follow parameters and inputs from now on."""
        self._phase = INITIALIZATION
        self._initial_dirty = True
        self._stale = set(self._all_groups)

    def exit_initialization_mode(self) -> None:
        """Validate the parameters, build the component(s) and start from the current inputs."""
        try:
            self._prepare_initial_state()
        except Exception as exc:  # noqa: BLE001 - every failure must reach the host with its message
            self._fail("exitInitializationMode", exc)
        self._phase = STEPPING
        self._time = self._start_time

    def _prepare_initial_state(self) -> None:
        if self._params_dirty:
            self._configure()
            self._configured_params = tuple(self._values[i] for i in self._parameter_vrs)
            self._params_dirty = False
        self._initialize(self._start_time)
        self._initial_dirty = False
        self._stale = set(self._all_groups)

    def do_step(self, current_time: float, step_size: float) -> bool:
        """One communication step; ``False`` (``fmi2Discard``) if the component could not take it.

        Hot path (every communication step): one chained comparison checks the phase-independent
        arguments (NaN fails every comparison), the eager groups are refreshed, and the stale set
        is only rebuilt when the FMU has lazy groups.
        """
        if self._phase != STEPPING or not (-_INF < current_time < _INF and 0.0 < step_size < _INF):
            return self._refuse_step(current_time, step_size)
        try:
            self._step(current_time, step_size)
        except Exception as exc:  # noqa: BLE001
            return self._step_failed(current_time, step_size, exc)
        self._time = current_time + step_size
        for group in self._eager_groups:
            self._refresh(group)
        if self._lazy_groups:
            self._stale = set(self._lazy_groups)
        elif self._stale:
            self._stale = set()
        return True

    def _refuse_step(self, current_time: float, step_size: float) -> bool:
        """``doStep`` outside the stepping phase or with a time or step that is not a finite number (> 0)."""
        if self._phase != STEPPING:
            self._report(f"doStep at t = {current_time:g} s called in phase {self._phase!r} (call exitInitializationMode first)")
        else:
            self._report(f"doStep refused: communication point {current_time!r} s and step {step_size!r} s must be "
                         "finite numbers, the step > 0; state kept")
        return False

    def _step_failed(self, current_time: float, step_size: float, exc: Exception) -> bool:
        """A step that raised: a model failure is a discard (state kept), anything else reaches the host as fatal."""
        if not (isinstance(exc, DtcosimError) or is_arithmetic_failure(exc)):
            self._fail(f"doStep from t = {current_time:.9g} s", exc)
        self._report(f"doStep from t = {current_time:.9g} s, h = {step_size:.3g} s failed: {plain_reason(exc)}; "
                     "state kept at the start of the step")
        return False

    def terminate(self) -> None:
        """Terminate the simulation run."""
        self._phase = TERMINATED

    # ---------------------------------------------------------------- get/set
    def _refresh_outputs(self, vrs: Iterable[int]) -> None:
        group_of = self._group_of
        groups = [group_of[vr] for vr in vrs if vr in group_of]
        if not groups:
            return
        if self._phase != STEPPING and self._initial_dirty:
            self._prepare_initial_state()
        stale = self._stale
        for group in groups:
            if group in stale:
                self._refresh(group)
                stale.discard(group)

    def _get(self, vrs: list[int], allowed: frozenset[int], type_name: str) -> list[Value]:
        try:
            if not allowed.issuperset(vrs):
                bad = [vr for vr in vrs if vr not in allowed]
                raise TypeError(f"value references {bad} are not {type_name} variables of {type(self).__name__}")
            if self._stale:
                self._refresh_outputs(vrs)
            values = self._values
            return [values[vr] for vr in vrs]
        except Exception as exc:  # noqa: BLE001
            self._fail(f"get{type_name}", exc)

    def _set(self, vrs: list[int], new_values: list[Value], allowed: frozenset[int], type_name: str) -> None:
        try:
            if not allowed.issuperset(vrs):
                bad = [vr for vr in vrs if vr not in allowed]
                raise TypeError(f"value references {bad} are not {type_name} variables of {type(self).__name__}")
            values = self._values
            kind = self._kind
            stepping = self._phase == STEPPING
            for vr, value in zip(vrs, new_values):
                causality = kind[vr][1]
                if causality == INPUT:
                    values[vr] = value
                elif causality == PARAMETER:
                    if stepping:
                        self._report(f"parameter {self.variables[vr].name} is fixed after initialisation; "
                                     f"the new value {value!r} is ignored", Fmi2Status.warning)
                        continue
                    values[vr] = value
                    self._params_dirty = True
                else:
                    raise TypeError(f"{self.variables[vr].name} is an output and cannot be set")
            if not stepping:
                self._initial_dirty = True
                self._stale = set(self._all_groups)
        except Exception as exc:  # noqa: BLE001
            self._fail(f"set{type_name}", exc)

    def get_real(self, vrs: list[int]) -> list[float]:
        """fmi2GetReal (hot path: plain look-ups once the requested outputs are current)."""
        stale = self._stale
        if (not stale or stale.isdisjoint(map(self._group_of.get, vrs))) and self._real_vrs.issuperset(vrs):
            values = self._values
            return [values[vr] for vr in vrs]
        return self._get(vrs, self._real_vrs, "Real")

    def get_integer(self, vrs: list[int]) -> list[int]:
        """fmi2GetInteger."""
        return self._get(vrs, self._integer_vrs, "Integer")

    def get_boolean(self, vrs: list[int]) -> list[bool]:
        """fmi2GetBoolean."""
        return self._get(vrs, self._boolean_vrs, "Boolean")

    def get_string(self, vrs: list[int]) -> list[str]:
        """fmi2GetString (no String variables)."""
        return self._get(vrs, frozenset(), "String")

    def set_real(self, vrs: list[int], values: list[float]) -> None:
        """fmi2SetReal (hot path: inputs while stepping are stored without further checks)."""
        if self._phase == STEPPING and self._real_input_vrs.issuperset(vrs):
            store = self._values
            for vr, value in zip(vrs, values):
                store[vr] = value
            return
        self._set(vrs, values, self._real_vrs, "Real")

    def set_integer(self, vrs: list[int], values: list[int]) -> None:
        """fmi2SetInteger."""
        self._set(vrs, [int(v) for v in values], self._integer_vrs, "Integer")

    def set_boolean(self, vrs: list[int], values: list[bool]) -> None:
        """fmi2SetBoolean."""
        self._set(vrs, [bool(v) for v in values], self._boolean_vrs, "Boolean")

    def set_string(self, vrs: list[int], values: list[str]) -> None:
        """fmi2SetString (no String variables)."""
        self._set(vrs, list(values), frozenset(), "String")

    # ---------------------------------------------------------------- FMU state
    def _get_fmu_state(self) -> dict[str, Any]:
        """Complete state: every variable value, the life-cycle flags and the component state."""
        try:
            configured = self._configured_params is not None and not self._params_dirty
            return {
                "format": STATE_FORMAT,
                "fmu": type(self).__name__,
                "build_id": self.build_id,
                "phase": self._phase,
                "start_time": self._start_time,
                "time": self._time,
                "initial_dirty": self._initial_dirty,
                "values": list(self._values),
                "component": self._component_state() if configured else None,
            }
        except Exception as exc:  # noqa: BLE001
            self._fail("getFMUstate", exc)

    def _set_fmu_state(self, state: dict[str, Any]) -> None:
        """Restore a state from :meth:`_get_fmu_state` (possibly deserialised, possibly taken by another instance)."""
        try:
            if not isinstance(state, dict) or state.get("format") != STATE_FORMAT or state.get("fmu") != type(self).__name__:
                raise ValueError(f"not a {type(self).__name__} FMU state of format {STATE_FORMAT}")
            values = list(state["values"])
            if len(values) != len(self._values):
                raise ValueError(f"state holds {len(values)} values, this FMU has {len(self._values)} variables")
            self._values[:] = values  # in place: the registered getters are bound to this list
            self._phase = state["phase"]
            self._start_time = float(state["start_time"])
            self._time = float(state["time"])
            self._stale = set(self._all_groups)
            params = tuple(self._values[i] for i in self._parameter_vrs)
            if state["component"] is None:
                self._params_dirty = params != self._configured_params
                self._initial_dirty = True
                return
            if params != self._configured_params or self._params_dirty:
                self._configure()
                self._configured_params = params
                self._params_dirty = False
            self._restore_component_state(state["component"])
            self._initial_dirty = bool(state["initial_dirty"])
        except Exception as exc:  # noqa: BLE001
            self._fail("setFMUstate", exc)

    @staticmethod
    def _fmu_state_from_bytes(state: bytes) -> Any:
        """Deserialise; never raises (a bad buffer is reported by ``setFMUstate``, which knows the instance)."""
        try:
            return json.loads(state.decode("utf-8"))
        except Exception as exc:  # noqa: BLE001
            return {"format": None, "error": f"cannot deserialise the FMU state: {exc}"}
