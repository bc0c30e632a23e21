"""The values each FMU parameter accepts, as the FMU's own validation states them.

The parameter checks live in the components (``components.validation``: ``> 0``,
``within [1, 3]``, ...), not in a table. To document them without a second copy
that could drift, :func:`accepted_ranges` asks the slave: it configures a slave
instance with one parameter at a time set to probe values outside any sensible
range (NaN, -1e30, +1e30 for Reals; -1e9 for Integers) and collects what the
:class:`~components.errors.ParameterError` raised *for that parameter* says was
expected. Errors naming another parameter (e.g. ``f_max > f_min``) are coupled
constraints and are left to the descriptions.
"""

from __future__ import annotations

import importlib
import json
import math
import tempfile
from pathlib import Path
from typing import Any, Mapping

from components.errors import DtcosimError, ParameterError

from .slaves.interface import BOOLEAN, INPUT, INTEGER, OUTPUT, REAL

#: Probe values per FMI type (no large positive Integer: sizes such as n_harmonics would allocate it).
PROBES = {REAL: (math.nan, -1.0e30, 1.0e30), INTEGER: (-10**9,), BOOLEAN: ()}
_FINITENESS = ("a real number", "a finite real number")

INPUT_RANGE = "finite (else fmi2Discard)"
OUTPUT_RANGE = "calculated"


def slave_class(name: str) -> type:
    """The slave class of FMU ``name`` (from ``fmus.slaves``)."""
    from .build import FMU_SLAVES

    module, _ = FMU_SLAVES[name]
    return getattr(importlib.import_module(f"fmus.slaves.{module}"), name)


def _expected(instance, vr: int, value, defaults: list) -> str | None:
    """What the validation expected when parameter ``vr`` is ``value`` (None: accepted)."""
    instance._values[:] = defaults
    instance._values[vr] = value
    try:
        instance._configure()
    except ParameterError as exc:
        if exc.name == instance.variables[vr].name:
            return str(exc.expected)
    except DtcosimError:
        pass
    return None


def accepted_ranges(name: str, model: Mapping[str, Any]) -> dict[str, str]:
    """``{variable: accepted values}`` for every variable of FMU ``name`` built from the record ``model``.

    Parameters get what their validation demands (``"> 0"``, ``"within [1, 3]"``,
    ``"0 = none, 1 = torque_step, ..."``; ``"finite"`` when only NaN/infinity are
    refused; ``"any"`` when nothing was refused); inputs :data:`INPUT_RANGE`,
    outputs :data:`OUTPUT_RANGE`.
    """
    from .records import full_record
    from .slaves.record import RECORD_FILE

    cls = slave_class(name)
    with tempfile.TemporaryDirectory(prefix="dtcosim_ranges_") as resources:
        (Path(resources) / RECORD_FILE).write_text(json.dumps(full_record(name, cls.role, model, "")), encoding="utf-8")
        instance = cls(instance_name="ranges", resources=resources)
        defaults = list(instance._values)
        out: dict[str, str] = {}
        for vr, var in enumerate(instance.variables):
            if var.causality == INPUT:
                out[var.name] = INPUT_RANGE
                continue
            if var.causality == OUTPUT:
                out[var.name] = OUTPUT_RANGE
                continue
            if var.type == BOOLEAN:
                out[var.name] = "false, true"
                continue
            texts: list[str] = []
            for probe in PROBES[var.type]:
                text = _expected(instance, vr, probe, defaults)
                if text is not None and text not in texts:
                    texts.append(text)
            bounds = [t for t in texts if t not in _FINITENESS]
            if bounds:
                out[var.name] = " and ".join(bounds)
            elif texts:
                out[var.name] = "finite"
            else:
                out[var.name] = "any"
        instance._values[:] = defaults
    return out
