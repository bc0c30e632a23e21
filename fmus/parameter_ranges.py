"""The values each FMU parameter accepts, as the FMU's own validation states them.

The parameter checks live in the components (``components.validation``: ``> 0``,
``within [1, 3]``, ...), not in a table. To document and publish them without a
second copy that could drift, this module asks the slave: it configures a slave
instance with one parameter at a time set to probe values outside any sensible
range (NaN, -1e300, +1e300 for Reals; -1e9 for Integers) and collects what the
:class:`~components.errors.ParameterError` raised *for that parameter* says was
expected (:func:`accepted_ranges`, for the documentation) and the numeric range
the validator attached to it (:func:`parameter_bounds`: written into the FMU's
record and as FMI ``min``/``max``, so hosts check values before instantiating).
Errors naming another parameter (e.g. ``f_max > f_min``) are coupled
constraints and are left to the descriptions (and to the FMU's initialisation).
"""

from __future__ import annotations

import functools
import json
import math
import tempfile
from pathlib import Path
from typing import Any, Mapping

from components.errors import DtcosimError, ParameterError
from components.validation import Bounds

from . import registry
from .records import full_record
from .slaves.interface import BOOLEAN, INPUT, INTEGER, OUTPUT, REAL
from .slaves.record import RECORD_FILE

#: Probe values per FMI type (no large positive Integer: an uncapped size would allocate it; the error
#: for -1e9 carries the whole range, the upper limit included).
PROBES = {REAL: (math.nan, -1.0e300, 1.0e300), INTEGER: (-10**9,), BOOLEAN: ()}
_FINITENESS = ("a real number", "a finite real number")

INPUT_RANGE = "finite (else fmi2Discard)"
OUTPUT_RANGE = "calculated"


def _expected(instance, vr: int, value, defaults: list) -> ParameterError | None:
    """The validation's error for parameter ``vr`` set to ``value`` (None: accepted or another parameter's)."""
    instance._values[:] = defaults
    instance._values[vr] = value
    try:
        instance._configure()
    except ParameterError as exc:
        if exc.name == instance.variables[vr].name:
            return exc
    except DtcosimError:
        pass
    return None


@functools.lru_cache(maxsize=32)
def _probe(name: str, model_json: str) -> tuple[dict[str, str], dict[str, Bounds]]:
    """(documentation text, numeric bounds) of every variable of FMU ``name`` built from the model."""
    model = json.loads(model_json)
    kind = registry.kind(name)
    cls = kind.slave_class()
    texts_out: dict[str, str] = {}
    bounds_out: dict[str, Bounds] = {}
    with tempfile.TemporaryDirectory(prefix="dtcosim_ranges_") as resources:
        (Path(resources) / RECORD_FILE).write_text(json.dumps(full_record(name, kind.role, model, "")), encoding="utf-8")
        instance = cls(instance_name="ranges", resources=resources)
        defaults = list(instance._values)
        for vr, var in enumerate(instance.variables):
            if var.causality == INPUT:
                texts_out[var.name] = INPUT_RANGE
                continue
            if var.causality == OUTPUT:
                texts_out[var.name] = OUTPUT_RANGE
                continue
            if var.type == BOOLEAN:
                texts_out[var.name] = "false, true"
                continue
            texts: list[str] = []
            for probe in PROBES[var.type]:
                exc = _expected(instance, vr, probe, defaults)
                if exc is None:
                    continue
                text = str(exc.expected)
                if text not in texts:
                    texts.append(text)
                if exc.bounds is not None and var.name not in bounds_out:
                    bounds_out[var.name] = exc.bounds
            bounds = [t for t in texts if t not in _FINITENESS]
            if bounds:
                texts_out[var.name] = " and ".join(bounds)
            elif texts:
                texts_out[var.name] = "finite"
            else:
                texts_out[var.name] = "any"
        instance._values[:] = defaults
    return texts_out, bounds_out


def parameter_bounds(name: str, model: Mapping[str, Any]) -> dict[str, Bounds]:
    """``{parameter: Bounds}`` of every parameter of FMU ``name`` whose validation has a simple range."""
    return dict(_probe(name, json.dumps(model, sort_keys=True))[1])


def accepted_ranges(name: str, model: Mapping[str, Any]) -> dict[str, str]:
    """``{variable: accepted values}`` for every variable of FMU ``name`` built from the record ``model``.

    Parameters get what their validation demands (``"> 0"``, ``"within [1, 3]"``,
    ``"0 = none, 1 = torque_step, ..."``; ``"finite"`` when only NaN/infinity are
    refused; ``"any"`` when nothing was refused); inputs :data:`INPUT_RANGE`,
    outputs :data:`OUTPUT_RANGE`.
    """
    return dict(_probe(name, json.dumps(model, sort_keys=True))[0])
