"""The FMU's record the build writes into each FMU (``resources/dtcosim.json``, see :mod:`fmus.slaves.record`).

:func:`full_record` gives the whole record: role, what the model was made from, the
model itself (:meth:`fmus.registry.FmuKind.model`: the parameter set the FMU is built
from, its structure and defaults), and the signals the slave declares for its outputs.
"""

from __future__ import annotations

from typing import Any, Iterable, Mapping

import components
from .slaves.interface import Variable
from .slaves.record import RECORD_FORMAT


def signals_of(variables: Iterable[Variable]) -> dict[str, dict[str, str]]:
    """Declared signals of a slave's variables: ``{variable: {"signal": kind, **info}}``."""
    return {v.name: {"signal": v.signal, **dict(v.info)} for v in variables if v.signal}


def full_record(name: str, role: str, model: Mapping[str, Any], source: str,
                variables: Iterable[Variable] = (), bounds: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The complete FMU record of FMU ``name`` (format :data:`~fmus.slaves.record.RECORD_FORMAT`).

    ``variables`` give the record's ``signals`` and ``unit_exponents`` (variable -> the parameter
    holding the exponent ``e`` of its unit, e.g. ``"stage1.k0": "stage1.exponent"`` for ``N/m^e``).

    ``bounds`` (parameter -> :class:`components.validation.Bounds`) become the record's
    ``bounds``: what a host checks a value against before it instantiates the FMU.
    """
    record = {
        "format": RECORD_FORMAT,
        "fmu": name,
        "role": role,
        "dtcosim": components.__version__,
        "source": source,
        "model": dict(model),
        "signals": signals_of(variables),
    }
    exponents = {v.name: v.unit_exponent for v in variables if v.unit_exponent}
    if exponents:  # "stage1.k0": "stage1.exponent": the parameter holding the e of its unit N/m^e
        record["unit_exponents"] = exponents
    if bounds:
        record["bounds"] = {var: b.as_dict() for var, b in bounds.items()}
    return record
