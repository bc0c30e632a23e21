"""FMU instances driven through fmpy's ``FMU2Slave`` and its raw FMI functions.

The master calls the C functions (``fmi2DoStep``, ``fmi2SetReal``,
``fmi2GetReal``) directly with pre-built value-reference and value arrays, which
saves fmpy's per-call list/array conversions (the plumbing cost per
communication step is measured in ``benchmarks/bench_plumbing.py``).

Every instance gets its own logger callback that keeps the FMU's last log
messages, and is instantiated with logging on: pythonfmu slaves report a Python
exception only through the logger, so this is how error messages reach the user.

Each FMU file is extracted once per process (cached by SHA-256), within the archive
limits of :func:`fmus.archive_checks.extract_fmu`. Shared
libraries are never unloaded: pythonfmu's runtime does not survive being
unloaded and loaded again in one process.
"""

from __future__ import annotations

from collections import deque
from ctypes import (
    CFUNCTYPE,
    PYFUNCTYPE,
    addressof,
    byref,
    c_double,
    c_int,
    c_size_t,
    c_uint,
    c_void_p,
    cast,
)
from pathlib import Path
from typing import Any, Iterable

from ..archive_members import shown_path
from ..errors import FmuStepError, InitializationError, status_label
from .fmu_interface import FmuInterface
from .unpacked_fmus import unpacked

FMI_OK, FMI_WARNING, FMI_ERROR, FMI_FATAL = 0, 1, 3, 4

#: our own prototypes of the hot FMI functions (FMI 2.0 fmi2Functions.h), called with plain addresses:
#: fmi2DoStep(c, currentCommunicationPoint, communicationStepSize, noSetFMUStatePriorToCurrentPoint)
DO_STEP = CFUNCTYPE(c_int, c_void_p, c_double, c_double, c_int)
#: fmi2GetReal / fmi2SetReal(c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
REAL_VALUES = CFUNCTYPE(c_int, c_void_p, c_void_p, c_size_t, c_void_p)
#: the same prototypes called with the GIL held, for FMUs whose functions run Python in this
#: interpreter (:func:`runs_python`): their wrapper takes the GIL on entry and releases it on
#: return, so releasing it around the call only adds a hand-over each way (~0.3-0.5 us per call,
#: eight calls per communication step in the paper system: ``benchmarks/bench_plumbing.py``)
DO_STEP_HOLDING_GIL = PYFUNCTYPE(c_int, c_void_p, c_double, c_double, c_int)
REAL_VALUES_HOLDING_GIL = PYFUNCTYPE(c_int, c_void_p, c_void_p, c_size_t, c_void_p)


def runs_python(iface: FmuInterface) -> bool:
    """True for a PythonFMU (dtcosim's FMUs among them): its FMI functions execute Python code in this process.

    Such functions need the GIL themselves (pythonfmu's C++ wrapper calls
    ``PyGILState_Ensure``), so the master calls them without releasing it
    (:data:`DO_STEP_HOLDING_GIL`); FMUs of other tools (compiled C) are called
    with the GIL released, so other Python threads keep running meanwhile.
    """
    return "pythonfmu" in iface.generation_tool.lower()


def hot_prototypes(iface: FmuInterface) -> tuple:
    """``(do_step prototype, get/set prototype)`` the master uses for this FMU (see :func:`runs_python`)."""
    if runs_python(iface):
        return DO_STEP_HOLDING_GIL, REAL_VALUES_HOLDING_GIL
    return DO_STEP, REAL_VALUES


#: log message lists of the live instances by instance name (see FmuInstance)
_LOG_SINKS: dict[str, deque] = {}


def _extract(iface: FmuInterface) -> Path:
    """Directory with the FMU's contents: unpacked once per content into the user cache (:mod:`.unpacked_fmus`)."""
    from fmus.archive_checks import FmuArchiveError, extract_fmu

    try:
        target = unpacked(iface.path, iface.sha256, extract_fmu)  # bounded: the archive limits hold whatever its
    except FmuArchiveError as exc:  # directory says; a damaged member, a zip bomb, a member outside the folder
        raise InitializationError(f"cannot extract the FMU: {exc}") from None
    except OSError as exc:  # a full disk, a file-size limit, a read-only temporary folder
        reason = exc.strerror or str(exc) or type(exc).__name__
        where = f" into {exc.filename}" if exc.filename else ""
        raise InitializationError(f"cannot extract the FMU {shown_path(iface.path)}{where}: {reason}") from None
    return target


class FmuInstance:
    """One co-simulation FMU instance.

    Parameters
    ----------
    name : str
        Instance name (the scenario's component name).
    interface : FmuInterface
        The FMU's model description.
    log_size : int
        Number of log messages kept.

    Attributes
    ----------
    component : int
        The ``fmi2Component`` handle (as an integer address).
    do_step, set_real, get_real : ctypes function
        The FMU's FMI functions with this module's prototypes (:data:`DO_STEP`,
        :data:`REAL_VALUES`, or their GIL-holding twins for a PythonFMU: :func:`hot_prototypes`);
        call as ``do_step(component, t, h, 1)``,
        ``set_real(component, address_of_vrs, n, address_of_values)``.
    log : collections.deque of str
        Last log messages, formatted ``"[status] category: message"``.
    """

    def __init__(self, name: str, interface: FmuInterface, log_size: int = 50) -> None:
        from fmpy import calloc, free
        from fmpy.fmi2 import (
            FMU2Slave,
            fmi2CallbackAllocateMemoryTYPE,
            fmi2CallbackFreeMemoryTYPE,
            fmi2CallbackFunctions,
            fmi2CallbackLoggerTYPE,
        )

        self.name = name
        self.interface = interface
        self.log: deque[str] = deque(maxlen=log_size)
        self.state = "loaded"  # loaded, instantiated, initialization, step, failed, freed
        self._failed_status = FMI_OK
        unzip = _extract(interface)
        self.slave = FMU2Slave(
            guid=interface.guid,
            unzipDirectory=str(unzip),
            modelIdentifier=interface.model_identifier,
            instanceName=name,
        )

        def logger(env, instance, status, category, message):
            text = message.decode("utf-8", "replace") if message else ""
            cat = category.decode("utf-8", "replace") if category else ""
            name = instance.decode("utf-8", "replace") if instance else ""
            # pythonfmu 0.7 may deliver a message through another instance's callbacks:
            # route it by the instance name it carries
            sink = _LOG_SINKS.get(name, self.log)
            sink.append(f"[{status_label(status)}] {cat + ': ' if cat else ''}{text}")

        cb = fmi2CallbackFunctions()
        cb.logger = fmi2CallbackLoggerTYPE(logger)
        cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        try:
            from fmpy.logging import addLoggerProxy

            addLoggerProxy(byref(cb))
        except Exception:  # pragma: no cover - the proxy only formats variadic arguments
            pass
        self._callbacks = cb
        self._logger = logger  # keep the ctypes callback alive
        dll = self.slave.dll  # fmpy's loaded shared library (public attribute)
        do_step_type, values_type = hot_prototypes(interface)
        self.do_step = do_step_type(cast(getattr(dll, "fmi2DoStep"), c_void_p).value)
        self.set_real = values_type(cast(getattr(dll, "fmi2SetReal"), c_void_p).value)
        self.get_real = values_type(cast(getattr(dll, "fmi2GetReal"), c_void_p).value)
        #: fmi2Get/SetInteger, -Boolean, -String by FMI type (same argument layout: pointers to arrays)
        self.typed_get = {typ: values_type(cast(getattr(dll, f"fmi2Get{typ}"), c_void_p).value)
                          for typ in ("Integer", "Boolean", "String")}
        self.typed_set = {typ: values_type(cast(getattr(dll, f"fmi2Set{typ}"), c_void_p).value)
                          for typ in ("Integer", "Boolean", "String")}
        self.component: Any = None

    # ----------------------------------------------------------------- checks
    def _check(self, status: int, function: str, time_s: float) -> int:
        if status > FMI_WARNING:
            self.mark_failed(status)
            raise FmuStepError(self.name, function, time_s, status, list(self.log))
        return status

    def mark_failed(self, status: int) -> None:
        """Remember that the FMU returned ``status`` (>= discard): limits the cleanup calls."""
        self.state = "failed"
        self._failed_status = max(self._failed_status, int(status))

    def _call(self, function: str, time_s: float, fn, *args) -> int:
        """Call a high-level fmpy method; turn its exception into FmuStepError with the log."""
        from fmpy.fmi1 import FMICallException

        try:
            fn(*args)
        except FMICallException as exc:
            self.mark_failed(exc.status)
            raise FmuStepError(self.name, function, time_s, exc.status, list(self.log)) from None
        except Exception as exc:  # instantiate returns NULL -> plain Exception
            self.mark_failed(FMI_ERROR)
            raise FmuStepError(self.name, function, time_s, FMI_ERROR, list(self.log) + [str(exc)]) from None
        return FMI_OK

    # -------------------------------------------------------------- lifecycle
    def instantiate(self, start_s: float, stop_s: float | None) -> None:
        """fmi2Instantiate (logging on) and fmi2SetupExperiment."""
        _LOG_SINKS[self.name] = self.log
        self._call("fmi2Instantiate", start_s, self.slave.instantiate, False, self._callbacks, True)
        self.component = self.slave.component
        self.state = "instantiated"
        _LOG_SINKS[self.name] = self.log
        self._call("fmi2SetupExperiment", start_s, self.slave.setupExperiment, None, start_s, stop_s)

    def enter_initialization(self, start_s: float) -> None:
        """fmi2EnterInitializationMode."""
        self._call("fmi2EnterInitializationMode", start_s, self.slave.enterInitializationMode)
        self.state = "initialization"

    def exit_initialization(self, start_s: float) -> None:
        """fmi2ExitInitializationMode."""
        self._call("fmi2ExitInitializationMode", start_s, self.slave.exitInitializationMode)
        self.state = "step"

    def set_values(self, values: dict[str, Any], time_s: float) -> None:
        """Set variables by name (any FMI type), e.g. parameters before initialisation."""
        by_type: dict[str, tuple[list[int], list[Any]]] = {}
        for name, value in values.items():
            var = self.interface.variables[name]
            vrs, vals = by_type.setdefault(var.type, ([], []))
            vrs.append(var.value_reference)
            vals.append(value)
        setters = {
            "Real": (self.slave.setReal, "fmi2SetReal", float),
            "Integer": (self.slave.setInteger, "fmi2SetInteger", int),
            "Enumeration": (self.slave.setInteger, "fmi2SetInteger", int),
            "Boolean": (self.slave.setBoolean, "fmi2SetBoolean", bool),
            "String": (self.slave.setString, "fmi2SetString", str),
        }
        for typ, (vrs, vals) in by_type.items():
            fn, fname, conv = setters[typ]
            self._call(fname, time_s, fn, vrs, [conv(v) for v in vals])

    def get_reals(self, names: Iterable[str], time_s: float) -> list[float]:
        """Real values by variable name."""
        names = list(names)
        vrs = (c_uint * len(names))(*(self.interface.variables[n].value_reference for n in names))
        vals = (c_double * len(names))()
        self._check(self.get_real(self.component, addressof(vrs), len(names), addressof(vals)), "fmi2GetReal", time_s)
        return list(vals)

    def get_values(self, names: Iterable[str], time_s: float) -> list[Any]:
        """Values of any FMI type by variable name (Real float, Integer/Enumeration int, Boolean bool, String str)."""
        getters = {"Real": self.slave.getReal, "Integer": self.slave.getInteger, "Enumeration": self.slave.getInteger,
                   "Boolean": self.slave.getBoolean, "String": self.slave.getString}
        out = []
        for name in names:
            var = self.interface.variables[name]
            box: list = []
            self._call(f"fmi2Get{'Integer' if var.type == 'Enumeration' else var.type}", time_s,
                       lambda: box.extend(getters[var.type]([var.value_reference])))
            value = box[0]
            out.append(value.decode("utf-8", "replace") if isinstance(value, bytes) else
                       bool(value) if var.type == "Boolean" else value)
        return out

    def termination_status(self) -> tuple[bool, float | None]:
        """After fmi2DoStep returned fmi2Discard: (fmi2Terminated, fmi2LastSuccessfulTime or None).

        Uses ``fmi2GetBooleanStatus`` and ``fmi2GetRealStatus``; an FMU that cannot tell
        (the call fails) counts as not terminated.
        """
        from fmpy.fmi2 import fmi2LastSuccessfulTime, fmi2Terminated

        try:
            terminated = bool(self.slave.getBooleanStatus(fmi2Terminated))
        except Exception:
            return False, None
        try:
            last = float(self.slave.getRealStatus(fmi2LastSuccessfulTime))
        except Exception:
            last = None
        return terminated, last

    def set_reals(self, values: dict[str, float], time_s: float) -> None:
        """Real values by variable name."""
        names = list(values)
        vrs = (c_uint * len(names))(*(self.interface.variables[n].value_reference for n in names))
        vals = (c_double * len(names))(*(float(values[n]) for n in names))
        self._check(self.set_real(self.component, addressof(vrs), len(names), addressof(vals)), "fmi2SetReal", time_s)

    def close(self) -> None:
        """fmi2Terminate and fmi2FreeInstance as far as the FMU's state allows.

        After fmi2Error only fmi2FreeInstance is called; after fmi2Fatal nothing
        (FMI 2: the instance is unusable). Never raises.
        """
        if self.component is None or self.state == "freed":
            return
        try:
            if self.state in ("step", "initialization", "failed") and self._failed_status < FMI_ERROR:
                self.slave.fmi2Terminate(self.component)
        except Exception:
            pass
        if self._failed_status < FMI_FATAL:
            try:
                self.slave.fmi2FreeInstance(self.component)
            except Exception:
                pass
        self.state = "freed"
        self.component = None
        if _LOG_SINKS.get(self.name) is self.log:
            del _LOG_SINKS[self.name]


def value_references(iface: FmuInterface, names: Iterable[str]):
    """A ctypes ``fmi2ValueReference`` array for the named variables."""
    names = list(names)
    return (c_uint * len(names))(*(iface.variables[n].value_reference for n in names))

