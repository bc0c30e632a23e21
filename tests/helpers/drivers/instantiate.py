"""Instantiate one FMU a few times through fmpy and report what happened, as JSON (imports nothing from dtcosim).

Usage: ``python instantiate.py FMU ATTEMPTS LOGGING_ON(0|1)``. Prints
``{"attempts": [{"ok": bool, "error": str | None}], "messages": [[status, text], ...]}``;
a successful instance is set up, initialised, stepped once and freed. The exit code is 0
whenever this process survives.
"""

from __future__ import annotations

import json
import sys

from fmpy import calloc, extract, free, read_model_description
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)


def main(path: str, attempts: int, logging_on: bool) -> dict:
    md = read_model_description(path)
    unzipped = extract(path)
    messages = []

    def logger(environment, instance, status, category, message):
        messages.append([int(status), message.decode("utf-8", "replace") if message else ""])

    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(logger)
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    results = []
    for i in range(attempts):
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                        instanceName=f"attempt{i}")
        try:
            fmu.instantiate(callbacks=callbacks, loggingOn=logging_on)
        except Exception as exc:  # noqa: BLE001 - fmpy raises on a NULL instance
            results.append({"ok": False, "error": str(exc)})
            continue
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=1e-3)
        fmu.terminate()
        fmu.freeInstance()
        results.append({"ok": True, "error": None})
    return {"attempts": results, "messages": messages}


if __name__ == "__main__":
    print(json.dumps(main(sys.argv[1], int(sys.argv[2]), sys.argv[3] == "1")))
