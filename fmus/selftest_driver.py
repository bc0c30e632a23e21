"""Run each FMU once through a bare fmpy loop and report as JSON (the host side of ``dtcosim validate --host``).

This script imports nothing from dtcosim: it runs with the interpreter of a
virtual environment that holds only an FMU's declared requirements and fmpy.
For each FMU it instantiates (``loggingOn``), sets up, initialises with the
start values, takes ``STEPS`` communication steps of the default step size,
reads every Real output, terminates and frees the instance.

While the FMUs run it records every absolute ``import`` executed by the FMUs'
own code (modules named ``_dtcosim_*``), so the report says which third-party
modules an FMU used: fmpy pulls numpy into the environment by itself, and the
report is what proves that the FMU's declaration lists all it imports.

Usage: ``python selftest_driver.py STEPS FMU [FMU ...]``; prints one JSON
object ``{fmu path: {"ok", "error", "messages", "imports", "outputs"}}``.
"""

from __future__ import annotations

import builtins
import json
import math
import sys

from fmpy import calloc, extract, free, read_model_description
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)

FMU_CODE_PREFIX = "_dtcosim_"

_imports: set = set()
_original_import = builtins.__import__


def _auditing_import(name, globals=None, locals=None, fromlist=(), level=0):
    importer = (globals or {}).get("__name__") or ""
    if level == 0 and importer.startswith(FMU_CODE_PREFIX):
        _imports.add(name.split(".")[0])
    return _original_import(name, globals, locals, fromlist, level)


def third_party(names) -> list:
    """Names that are neither the standard library nor carried by the FMU."""
    return sorted(n for n in names if n not in sys.stdlib_module_names and not n.startswith(FMU_CODE_PREFIX)
                  and n not in ("pythonfmu", "__future__"))


def run_once(path: str, steps: int) -> dict:
    """Instantiate, initialise, step and free one FMU; never raises."""
    messages = []
    report = {"ok": False, "error": None, "messages": messages, "imports": [], "outputs": {}}
    _imports.clear()
    fmu = None
    try:
        md = read_model_description(path)
        step = float(md.defaultExperiment.stepSize) if md.defaultExperiment and md.defaultExperiment.stepSize else 1e-3
        outputs = [v for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                        instanceName="selftest")

        def logger(environment, instance, status, category, message):
            messages.append([int(status), message.decode("utf-8", "replace") if message else ""])

        callbacks = fmi2CallbackFunctions()
        callbacks.logger = fmi2CallbackLoggerTYPE(logger)
        callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        fmu.instantiate(callbacks=callbacks, loggingOn=True)
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        for n in range(steps):
            status = fmu.doStep(currentCommunicationPoint=n * step, communicationStepSize=step)
            if status:
                raise RuntimeError("fmi2DoStep at t = %g s returned status %d" % (n * step, status))
        values = fmu.getReal([v.valueReference for v in outputs])
        report["outputs"] = {v.name: x for v, x in zip(outputs, values)}
        bad = [v.name for v, x in zip(outputs, values) if not math.isfinite(x)]
        if bad:
            raise RuntimeError("non-finite outputs after %d steps: %s" % (steps, ", ".join(bad)))
        fmu.terminate()
        report["ok"] = True
    except Exception as exc:  # noqa: BLE001 - the report says what failed
        report["error"] = "%s: %s" % (type(exc).__name__, exc)
    finally:
        if fmu is not None and getattr(fmu, "component", None):
            fmu.freeInstance()
    report["imports"] = third_party(_imports)
    return report


def main(argv) -> int:
    steps = int(argv[0])
    builtins.__import__ = _auditing_import
    try:
        result = {path: run_once(path, steps) for path in argv[1:]}
    finally:
        builtins.__import__ = _original_import
    json.dump(result, sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
