"""The record a dtcosim FMU carries of itself: ``resources/dtcosim.json``.

Written by the build (:mod:`fmus.records`), read by the slave at instantiation
(its ``model``: the parameter set the FMU's structure and defaults come from) and
by hosts that want to know what the FMU is (:mod:`orchestrator.cosim.fmu_interface`):

``format``
    :data:`RECORD_FORMAT`.
``fmu``, ``role``
    Model name and declared role (:data:`ROLES`).
``dtcosim``, ``source``
    The dtcosim version and what the model was made from (``"preset table6"``, a drivetrain file).
``model``
    The parameter set as plain data (:mod:`components.model.description`), plus
    operating-point defaults: WindSource ``{"wind"}``, Gearbox ``{"drivetrain",
    "rotor_speed_rad_s"}``, GeneratorRotor ``{"generator", "initial_speed_rad_s"}``.
``unit_exponents`` (optional)
    Variable -> the parameter whose value is the exponent ``e`` of its unit (``"stage1.k0":
    "stage1.exponent"``: k0 is in N/m^e); hosts convert quantities such as ``"5e5 N/mm^1.5"`` with it.
``signals``
    Output variable -> ``{"signal": kind, ...}`` (:data:`SIGNALS` of the role),
    e.g. ``"stage1.F_sp[1]": {"signal": "contact_force", "stage": "stage1", "mesh":
    "sun_planet", "planet": "1"}``. Analyses of a run use these, never the names.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

RECORD_FILE = "dtcosim.json"
RECORD_FORMAT = 1
#: record key of the start values a copy of an FMU was given (:mod:`fmus.start_values`)
START_VALUES_KEY = "start_values"

#: roles a component of a drivetrain co-simulation can have
WIND_SOURCE, GEARBOX, GENERATOR = "wind_source", "gearbox", "generator"
#: a recorded time series (TimeSeriesSource), a torque-driven rotor, a generator torque controller
TIME_SERIES, ROTOR, TORQUE_CONTROLLER = "time_series", "rotor", "torque_controller"
ROLES = (WIND_SOURCE, GEARBOX, GENERATOR, TIME_SERIES, ROTOR, TORQUE_CONTROLLER)

#: signal kinds an output can be declared as, per role; ``many``: any number of variables, else at most one
SIGNALS: dict[str, dict[str, bool]] = {
    WIND_SOURCE: {"rotor_speed": False, "rotor_angle": False, "rotor_acceleration": False, "rotor_jerk": False},
    GEARBOX: {"contact_force": True, "shaft_torque": True, "body_speed": True, "output_speed": False,
              "rotor_torque": False, "generator_shaft_torque": True, "output_acceleration_peak": False,
              "body_displacement": True, "bearing_force": True, "support_force": True, "bearing_speed": True,
              "support_torque": True},
    GENERATOR: {"generator_speed": False, "generator_angle": False, "generator_torque": False},
    # "recorded": a channel of a record, info {"channel", "unit" (as recorded), "quantity" (the signal kind
    # of another role it is the record of, e.g. generator_speed), "record"}
    TIME_SERIES: {"recorded": True},
    ROTOR: {"rotor_speed": False, "rotor_angle": False, "main_shaft_torque": False},
    TORQUE_CONTROLLER: {"generator_torque_demand": False, "filtered_generator_speed": False},
}


class FmuRecordError(Exception):
    """The FMU's record is missing or unreadable."""


def read_fmu_record(resources: str | Path | None) -> dict[str, Any]:
    """The record in the resources folder ``resources``.

    Raises
    ------
    FmuRecordError
        Naming the file and what is wrong with it.
    """
    if resources is None:
        raise FmuRecordError("no resources folder given: a dtcosim FMU reads its model from resources/" + RECORD_FILE)
    path = Path(resources) / RECORD_FILE
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise FmuRecordError(f"cannot read {path}: {exc.strerror or exc}") from None
    except ValueError as exc:
        raise FmuRecordError(f"{path} is not valid JSON: {exc}") from None
    if not isinstance(record, dict) or record.get("format") != RECORD_FORMAT or not isinstance(record.get("model"), dict):
        raise FmuRecordError(f"{path} is not a dtcosim record of format {RECORD_FORMAT}")
    if not isinstance(record.get(START_VALUES_KEY, {}), dict):
        raise FmuRecordError(f"{path}: {START_VALUES_KEY} must be a table of variable name -> value, "
                          f"not {record[START_VALUES_KEY]!r}")
    return record
