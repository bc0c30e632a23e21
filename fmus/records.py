"""The records the build writes into each FMU (``resources/dtcosim.json``, see :mod:`fmus.slaves.record`).

:func:`model_of` gives the parameter set an FMU is built from (its structure and
defaults), :func:`full_record` the whole record: role, what the model was made
from, and the signals the slave declares for its outputs.
"""

from __future__ import annotations

from typing import Any, Iterable, Mapping

import components
from components.model.description import describe
from components.model.drivetrain import Drivetrain
from components.model.rotor import RotorParameters
from components.model.torque_controller import TorqueLawParameters
from components.model.wind import WindParameters

from .slaves.interface import Variable
from .slaves.record import RECORD_FORMAT


def model_of(name: str, drivetrain: Drivetrain, wind: WindParameters | None = None) -> dict[str, Any]:
    """The record ``model`` of FMU ``name`` for a co-simulation drivetrain (with generator and output shaft).

    Parameters
    ----------
    name : {"WindSource", "Gearbox", "GeneratorRotor"}
    drivetrain : Drivetrain
        The gearbox structure and defaults, with the generator (its inertia and counter torque
        are the GeneratorRotor's defaults).
    wind : WindParameters, optional
        The rotor-speed defaults (default: the paper's, Sec. 4.2); its mean speed sets the
        Gearbox's input start values and the generator's initial speed (``ratio * omega0``).
    """
    wind = wind or WindParameters()
    if name == "WindSource":
        return {"wind": describe(wind)}
    if name == "Gearbox":
        return {"drivetrain": describe(drivetrain), "rotor_speed_rad_s": wind.mean_speed_rad_s}
    if name == "GeneratorRotor":
        if drivetrain.generator is None:
            raise ValueError("a GeneratorRotor FMU needs a drivetrain with a generator")
        return {"generator": describe(drivetrain.generator),
                "initial_speed_rad_s": drivetrain.ratio * wind.mean_speed_rad_s}
    if name == "Rotor":
        return {"rotor": describe(RotorParameters()), "initial_speed_rad_s": wind.mean_speed_rad_s}
    if name == "TorqueController":
        return {"controller": describe(TorqueLawParameters()),
                "initial_speed_rad_s": drivetrain.ratio * wind.mean_speed_rad_s}
    raise ValueError(f"no record model for FMU {name!r}")


def signals_of(variables: Iterable[Variable]) -> dict[str, dict[str, str]]:
    """Declared signals of a slave's variables: ``{variable: {"signal": kind, **info}}``."""
    return {v.name: {"signal": v.signal, **dict(v.info)} for v in variables if v.signal}


def full_record(name: str, role: str, model: Mapping[str, Any], source: str,
                variables: Iterable[Variable] = (), bounds: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The complete record of FMU ``name`` (format :data:`~fmus.slaves.record.RECORD_FORMAT`).

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
    if bounds:
        record["bounds"] = {var: b.as_dict() for var, b in bounds.items()}
    return record
