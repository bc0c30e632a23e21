"""Run an SSP in libcosim (the OSP C++ co-simulation library, through ``libcosimpy``).

libcosim loads the pythonfmu FMUs as shared libraries that embed Python; the
Python runtime must already be in the process, so the run happens in a child
process started with ``LD_PRELOAD=<libpython>`` (:func:`libpython_path`).

``run_ssp_in_libcosim(ssp, stop_s, variables)`` returns the sampled variables
and the wall time of the simulation alone. The same module is the child's entry
point (``python -m orchestrator.interop.libcosim SSP --stop T --var comp.name ... --out result.npz``).

libcosim's fixed-step algorithm steps all FMUs from ``t_k`` to ``t_{k+1}`` and
then transfers every connected output (a Jacobi scheme, inputs held), with the
base step of the SSP's ``osp:FixedStepAlgorithm`` annotation.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import sysconfig
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from components.errors import DtcosimError

NANOSECONDS = 1_000_000_000


class LibcosimError(DtcosimError, RuntimeError):
    """libcosim could not load or run the SSP (message from ``cosim_last_error_message``)."""


def libpython_path() -> str:
    """Path of the shared libpython of this interpreter (to preload for libcosim)."""
    libdir = sysconfig.get_config_var("LIBDIR") or ""
    for key in ("INSTSONAME", "LDLIBRARY"):
        name = sysconfig.get_config_var(key)
        if name and name.endswith((".so", ".dylib")) or (name and ".so." in name):
            p = Path(libdir) / name
            if p.exists():
                return str(p)
    raise LibcosimError("this Python has no shared libpython (built without --enable-shared); libcosim cannot "
                        "load pythonfmu FMUs")


@dataclass
class LibcosimRun:
    """Samples of a libcosim run.

    Attributes
    ----------
    time_s : ndarray, shape (n,)
    values : dict of str -> ndarray, shape (n,)
        By ``component.variable``.
    simulation_wall_time_s : float
        Wall time of ``simulate_until`` alone [s].
    total_wall_time_s : float
        Child process wall time including loading the SSP [s].
    last : dict of str -> float, int, bool or str
        Values at the stop time of the ``last`` variables (any type, e.g. parameters
        the SSP set: what libcosim applied).
    """

    time_s: np.ndarray
    values: dict[str, np.ndarray]
    simulation_wall_time_s: float
    total_wall_time_s: float
    last: dict = None


def run_ssp_in_libcosim(ssp: str | Path, stop_s: float, variables: list[str], timeout_s: float = 600.0,
                        last: list[str] = ()) -> LibcosimRun:
    """Simulate an SSP with libcosim in a child process and return the sampled variables.

    Parameters
    ----------
    ssp : path
        ``.ssp`` archive, SSP directory or ``.ssd`` file.
    stop_s : float
        Stop time [s] (the run starts at the SSP's start time).
    variables : list of str
        ``component.variable`` names (Real) to sample at every step.
    timeout_s : float
        Child process timeout [s].
    last : list of str
        ``component.variable`` names (any type) whose values at the stop time are returned.
    """
    from .ssp import import_ssp

    sim = import_ssp(ssp).simulation  # libcosim steps with the SSP's osp:FixedStepAlgorithm base step
    n_steps = int(round((stop_s - sim.start_s) / sim.step_s))
    with tempfile.TemporaryDirectory(prefix="dtcosim-libcosim-") as tmp:
        out = Path(tmp) / "result.npz"
        cmd = [sys.executable, "-m", "orchestrator.interop.libcosim", str(ssp), "--stop", repr(float(stop_s)),
               "--samples", str(n_steps + 1), "--out", str(out)]
        for v in variables:
            cmd += ["--var", v]
        for v in last:
            cmd += ["--last", v]
        env = dict(os.environ)
        env["LD_PRELOAD"] = (libpython_path() + " " + env.get("LD_PRELOAD", "")).strip()
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=timeout_s)
        total = time.perf_counter() - t0
        if proc.returncode != 0 or not out.exists():
            raise LibcosimError(f"libcosim run failed (exit {proc.returncode}): {proc.stderr.strip()[-2000:]}")
        data = np.load(out)
        meta = json.loads(str(data["meta"]))
        return LibcosimRun(
            time_s=data["time_s"],
            values={v: data[f"v{i}"] for i, v in enumerate(variables)},
            simulation_wall_time_s=float(meta["simulation_wall_time_s"]),
            total_wall_time_s=total,
            last=dict(meta.get("last", {})),
        )


def _last_error() -> str:
    """libcosim's own message for the last failure (its Python wrapper raises a bare AssertionError)."""
    from libcosimpy._internal import get_last_error_message

    return get_last_error_message() or "(no message)"


def _real_samples(observer, slave_index: int, value_reference: int, count: int) -> tuple[np.ndarray, np.ndarray]:
    """All buffered samples of one Real variable from step 0: (times [s], values).

    Calls libcosimc's ``cosim_observer_slave_get_real_samples`` directly and keeps
    as many samples as it reports (libcosimpy 0.0.6 trims its result by counting
    zero step numbers, which drops the last sample).
    """
    from ctypes import POINTER, c_double, c_int, c_int64, c_size_t, c_uint32

    from libcosimpy._internal import libcosimc, wrap_function
    from libcosimpy.CosimObserver import CosimObserver

    get = wrap_function(
        lib=libcosimc(), funcname="cosim_observer_slave_get_real_samples", restype=c_int64,
        argtypes=[POINTER(CosimObserver), c_int, c_uint32, c_int64, c_size_t,
                  POINTER(c_double), POINTER(c_int64), POINTER(c_int64)],
    )
    values = (c_double * count)()
    steps = (c_int64 * count)()
    times = (c_int64 * count)()
    n = get(observer.ptr(), slave_index, value_reference, 0, count, values, steps, times)
    if n < 0:
        raise LibcosimError(f"cannot read samples of slave {slave_index}, variable {value_reference}: {_last_error()}")
    return np.asarray(times[:n], dtype=float) / NANOSECONDS, np.asarray(values[:n], dtype=float)


def _child(argv: list[str] | None = None) -> int:
    """Entry point of the child process (needs libpython preloaded)."""
    parser = argparse.ArgumentParser(description="run an SSP in libcosim and save sampled variables")
    parser.add_argument("ssp")
    parser.add_argument("--stop", type=float, required=True)
    parser.add_argument("--samples", type=int, required=True)
    parser.add_argument("--var", action="append", default=[])
    parser.add_argument("--last", action="append", default=[])
    parser.add_argument("--out", required=True)
    args = parser.parse_args(argv)

    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimObserver import CosimObserver

    try:
        execution = CosimExecution.from_ssp_file(str(Path(args.ssp).resolve()))
    except AssertionError:
        print(f"libcosim could not load {args.ssp}: {_last_error()}", file=sys.stderr)
        return 2
    slaves = {info.name.decode(): info.index for info in execution.slave_infos()}

    def lookup(v: str):
        comp, _, name = v.partition(".")
        if comp not in slaves:
            raise LibcosimError(f"no component {comp!r} in the SSP (have {', '.join(slaves)})")
        idx = slaves[comp]
        found = next((d for d in execution.slave_variables(idx) if d.name.decode() == name), None)
        if found is None:
            raise LibcosimError(f"no variable {name!r} in component {comp!r}")
        return idx, found.reference, found.type

    try:
        refs = [lookup(v)[:2] for v in args.var]
        last_refs = [lookup(v) for v in args.last]
    except LibcosimError as exc:
        print(exc, file=sys.stderr)
        return 2
    observer = CosimObserver.create_time_series(buffer_size=args.samples)
    execution.add_observer(observer)
    last_observer = CosimObserver.create_last_value()
    execution.add_observer(last_observer)
    for idx, vr in refs:
        observer.start_time_series(idx, vr, CosimVariableType.REAL)
    t0 = time.perf_counter()
    ok = execution.simulate_until(int(round(args.stop * NANOSECONDS)))
    wall = time.perf_counter() - t0
    if not ok:
        print(f"libcosim simulation failed: {_last_error()}", file=sys.stderr)
        return 3
    arrays = {}
    time_s = None
    for i, (idx, vr) in enumerate(refs):
        times, values = _real_samples(observer, idx, vr, args.samples)
        arrays[f"v{i}"] = values
        if time_s is None:
            time_s = times
    readers = {CosimVariableType.REAL.value: last_observer.last_real_values,
               CosimVariableType.INTEGER.value: last_observer.last_integer_values,
               CosimVariableType.BOOLEAN.value: last_observer.last_boolean_values,
               CosimVariableType.STRING.value: last_observer.last_string_values}
    last = {}
    for v, (idx, vr, typ) in zip(args.last, last_refs):
        value = readers[typ](idx, [vr])[0]
        last[v] = value.decode() if isinstance(value, bytes) else value
    np.savez(args.out, time_s=time_s if time_s is not None else np.zeros(0),
             meta=json.dumps({"simulation_wall_time_s": wall, "last": last}), **arrays)
    return 0


if __name__ == "__main__":
    sys.exit(_child())
