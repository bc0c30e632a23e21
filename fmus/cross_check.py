"""Each FMU's own cross-check: reference outputs of a stand-alone run with stated inputs, and the comparison.

An FMU dtcosim builds carries, in ``documentation/cross-check/``, the files of the FMI Cross-Check layout
(https://github.com/modelica/fmi-cross-check) for a stand-alone run of itself:

``<Model>_in.csv``
    The stated inputs: one row per communication point, ``"time"`` first, every input of the FMU (at its
    start value, except the ramps its :class:`CrossCheckCase` declares; angles are the exact integrals of
    their speeds, so that the inputs are consistent). A host sets each input to its row's value at each
    communication point.
``<Model>_ref.opt``
    ``StartTime``, ``StopTime``, ``StepSize`` (the communication step) and ``RelTol``.
``<Model>_ref.csv``
    Every output at every communication point, as this build computed it (fmpy as the host).

``dtcosim validate FMU --cross-check RESULT.csv`` compares another host's run of those inputs against the
reference: by the FMI Cross-Check's own rule (fmpy's ``cross_check.validate_result``: a band of 10 % of each
signal's range around the reference, at most 10 % of the samples outside it) and, stricter, by the largest
deviation of each output relative to its reference's range (at most ``RelTol`` by default), which is what a
host that runs the same binary with the same inputs should meet.
"""

from __future__ import annotations

import contextlib
import errno
import os
import signal
import stat
import tempfile
import threading
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

import numpy as np

from .archive_checks import extract_fmu
from .cross_check_case import CrossCheckCase, CrossCheckError, stated_inputs

#: where in the FMU the cross-check files are
MEMBER_DIR = "documentation/cross-check"
#: the RelTol written into ``<Model>_ref.opt``: the stricter comparison's default bound
REL_TOL = 1e-4
#: the largest result CSV read (a cross-check result of an FMU: kilobytes)
MAX_RESULT_BYTES = 256 << 20


def _csv_text(table: np.ndarray) -> str:
    """The structured array ``table`` as CSV: a header of quoted names, each cell ``repr(float(value))``."""
    columns = np.empty((len(table), len(table.dtype.names)))
    for i, name in enumerate(table.dtype.names):
        columns[:, i] = table[name]  # to float64 as float() converts each value
    lines = [",".join(f'"{n}"' for n in table.dtype.names)]
    lines += [",".join(map(repr, row)) for row in columns.tolist()]
    return "\n".join(lines) + "\n"


def _step_of(md) -> float:
    de = md.defaultExperiment
    return float(de.stepSize) if de is not None and de.stepSize not in (None, "") else 1e-3


def reference_members(fmu_path: Path, case: CrossCheckCase) -> dict[str, bytes]:
    """Run the FMU stand-alone (fmpy) with the stated inputs; the cross-check files by archive member name."""
    from fmpy import read_model_description, simulate_fmu

    md = read_model_description(str(fmu_path))
    model = md.coSimulation.modelIdentifier
    step = _step_of(md)
    inputs = stated_inputs(case, md, step)
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    with tempfile.TemporaryDirectory(prefix="dtcosim_cross_check_") as unzipped:
        try:
            extract_fmu(fmu_path, unzipped)
            with stop_signals_held():
                result = simulate_fmu(unzipped, start_time=case.start_time, stop_time=case.stop_time,
                                      step_size=step, output_interval=step,
                                      input=inputs if len(inputs.dtype.names) > 1 else None, output=outputs,
                                      validate=False, model_description=md)
        finally:
            forget_python_from(Path(unzipped))
    opt = f"StartTime,{case.start_time!r}\nStopTime,{case.stop_time!r}\nStepSize,{step!r}\nRelTol,{REL_TOL:g}\n"
    return {f"{MEMBER_DIR}/{model}_in.csv": _csv_text(inputs).encode(),
            f"{MEMBER_DIR}/{model}_ref.opt": opt.encode(),
            f"{MEMBER_DIR}/{model}_ref.csv": _csv_text(result[["time", *outputs]]).encode()}


#: the signals that stop a command (Ctrl-C, a scheduler's kill, a closed terminal)
STOP_SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name))


@contextlib.contextmanager
def stop_signals_held() -> Iterator[None]:
    """Stop signals that arrive during the block are held, and handed to the handlers in place before it once it has
    ended (which raise there, e.g. KeyboardInterrupt).

    The FMU's slave runs in this interpreter: a KeyboardInterrupt raised inside its ``do_step`` becomes an
    ``fmi2Error`` and the run a misleading "cross-check run failed" (a Ctrl-C during a first run's builds ended it
    with that message and status 1, not as interrupted). Held, the signal waits for the run's end (a fraction of a
    second). Only Python handlers are held, and only in the main thread (where they run).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held: list[int] = []
    previous = {s: signal.getsignal(s) for s in STOP_SIGNALS}
    previous = {s: h for s, h in previous.items() if callable(h)}
    for s in previous:
        signal.signal(s, lambda signum, frame: held.append(signum))
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
        if held:
            previous[held[0]](held[0], None)


def forget_python_from(folder: Path) -> None:
    """Drop from this process the modules an FMU run in it imported from ``folder`` (the FMU's extracted
    resources, about to be deleted) and the ``sys.path`` entries inside it: a later instance of the same FMU, from
    another folder, imports its own copy instead of reusing modules whose files are gone."""
    import importlib
    import sys

    root = os.path.realpath(folder) + os.sep
    heads: dict[str, str] = {}  # real paths by folder: a process's ~450 modules lie in a few dozen folders

    def real(path: str) -> str:  # os.path.realpath(path), resolving each folder once
        head, tail = os.path.split(path)
        if tail in ("", ".", "..") or os.path.islink(path):
            return os.path.realpath(path)
        if head not in heads:
            heads[head] = os.path.realpath(head)
        return os.path.join(heads[head], tail)

    def inside(path: object) -> bool:
        return isinstance(path, str) and real(path).startswith(root)

    for name, module in list(sys.modules.items()):
        if inside(getattr(module, "__file__", None)):
            del sys.modules[name]
    sys.path[:] = [entry for entry in sys.path if not inside(entry)]
    importlib.invalidate_caches()


# ----------------------------------------------------------------------------- comparison
@dataclass(frozen=True)
class SignalDeviation:
    """One output: the largest |result - reference| at the reference's times, relative to the reference's range."""

    name: str
    max_abs: float
    relative: float


@dataclass(frozen=True)
class CrossCheckReport:
    """Another host's result against an FMU's reference.

    Attributes
    ----------
    model : str
    rule_problem : str or None
        The FMI Cross-Check rule's verdict (None: passed).
    deviations : tuple of SignalDeviation
        Every output of the reference, worst first.
    rel_tol : float
        Bound of the stricter comparison.
    missing : tuple of str
        Reference outputs the result lacks.
    """

    model: str
    rule_problem: str | None
    deviations: tuple[SignalDeviation, ...]
    rel_tol: float
    missing: tuple[str, ...]

    @property
    def worst(self) -> SignalDeviation | None:
        return self.deviations[0] if self.deviations else None

    @property
    def passed(self) -> bool:
        return self.rule_problem is None and not self.missing and \
            all(d.relative <= self.rel_tol for d in self.deviations)


def _read_member_csv(archive: zipfile.ZipFile, name: str, what: str, fmu: Path) -> np.ndarray:
    from fmpy.util import read_csv

    try:
        data = archive.read(name)
    except KeyError:
        raise CrossCheckError(f"{fmu}: no {what} ({name}): the FMU was not built with a cross-check "
                              "(rebuild it with this dtcosim: `dtcosim build`)") from None
    return _parse_csv(data.decode(), f"{fmu}!{name}", read_csv)


def _parse_csv(text: str, where: str, read_csv) -> np.ndarray:
    with tempfile.NamedTemporaryFile("w", suffix=".csv", delete=False) as tmp:
        tmp.write(text)
    try:
        table = read_csv(tmp.name)
    except (ValueError, IndexError) as exc:
        raise CrossCheckError(f"{where}: not a CSV of the FMI Cross-Check layout (a header of quoted names, "
                              f"\"time\" first, one number per cell): {exc}") from None
    finally:
        Path(tmp.name).unlink()
    if not table.dtype.names or table.dtype.names[0] != "time":
        raise CrossCheckError(f"{where}: the first column must be \"time\" (FMI Cross-Check rules)")
    return table


def read_reference(fmu: Path) -> tuple[str, np.ndarray, dict[str, float]]:
    """``(model identifier, reference table, options)`` of the cross-check an FMU carries."""
    from fmpy import read_model_description

    model = read_model_description(str(fmu)).coSimulation.modelIdentifier
    with zipfile.ZipFile(fmu) as z:
        ref = _read_member_csv(z, f"{MEMBER_DIR}/{model}_ref.csv", "cross-check reference", fmu)
        try:
            lines = z.read(f"{MEMBER_DIR}/{model}_ref.opt").decode().splitlines()
        except KeyError:
            raise CrossCheckError(f"{fmu}: no {MEMBER_DIR}/{model}_ref.opt") from None
    opts = {k.strip(): float(v) for k, v in (line.split(",", 1) for line in lines if "," in line)}
    return model, ref, opts


def compare(fmu: str | Path, result_csv: str | Path, rel_tol: float | None = None) -> CrossCheckReport:
    """Compare a host's result (a CSV of the FMI Cross-Check layout) with the reference the FMU carries."""
    from fmpy.cross_check import validate_result
    from fmpy.util import read_csv

    fmu, result_csv = Path(fmu), Path(result_csv)
    model, ref, opts = read_reference(fmu)
    try:
        if not stat.S_ISREG(os.stat(result_csv).st_mode):  # a pipe or a device would block or never end
            raise OSError(errno.EINVAL, "not a regular file (a device, pipe or folder)")
        if os.stat(result_csv).st_size > MAX_RESULT_BYTES:
            raise OSError(errno.EFBIG, f"larger than {MAX_RESULT_BYTES >> 20} MiB")
        text = result_csv.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise CrossCheckError(f"{result_csv}: cannot read it: {exc}") from None
    result = _parse_csv(text, str(result_csv), read_csv)
    rule = validate_result(result=result, reference=ref, t_start=opts["StartTime"], t_stop=opts["StopTime"])
    names = ref.dtype.names[1:]
    missing = tuple(n for n in names if n not in result.dtype.names)
    t_res, t_ref = result["time"], ref["time"]
    devs = []
    for name in names:
        if name in missing:
            continue
        y = np.interp(t_ref, t_res, result[name])
        err = float(np.max(np.abs(y - ref[name])))
        scale = max(float(np.ptp(ref[name])), 1e-2 * float(np.max(np.abs(ref[name]))), 1e-300)
        devs.append(SignalDeviation(name, err, err / scale))
    devs.sort(key=lambda d: -d.relative)
    return CrossCheckReport(model, rule, tuple(devs), rel_tol if rel_tol is not None else opts.get("RelTol", REL_TOL),
                            missing)
