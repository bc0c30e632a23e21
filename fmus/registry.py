"""What each dtcosim FMU is, declared once: the registry every other module reads.

One :class:`FmuKind` per FMU this project builds: its model name (the FMU file is
``<name>.fmu``), its slave class (:mod:`fmus.slaves`), its role in a drivetrain
(:data:`fmus.slaves.record.ROLES`, written into the FMU's record), what it is built
from (a preset, a drivetrain file, a load record), the record ``model`` of a
drivetrain (its structure and defaults), its part of the initialisation order
and its hand-written documentation page (``fmus/doc_content/<name>.html``).

The build (:mod:`fmus.build`), the documentation (:mod:`fmus.documentation`), the
probe of parameter ranges (:mod:`fmus.parameter_ranges`), the scenario format
(which file a drivetrain file or a load record builds) and the provisioning
(:mod:`orchestrator.provision`) all ask this module; none of them keeps a list of
FMU names or tests an FMU by its file name. Adding an FMU: a slave module under
``fmus/slaves/``, a page in ``fmus/doc_content/`` and one entry in :data:`KINDS`.

The slave modules are imported only when a slave class is asked for
(:meth:`FmuKind.slave_class`): reading the registry costs no pythonfmu import.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from components.model.description import describe
from components.model.drivetrain import Drivetrain
from components.model.presets import PRESETS, cosim_preset
from components.model.rotor import RotorParameters
from components.model.torque_controller import TorqueLawParameters
from components.model.wind import WindParameters

from .cross_check_case import CrossCheckCase, Ramp
from .slaves.record import GEARBOX, GENERATOR, ROTOR, TIME_SERIES, TORQUE_CONTROLLER, WIND_SOURCE

#: what an FMU is built from: a drivetrain preset, a drivetrain file (``drivetrain = "..."`` in a scenario),
#: a load record (``[components.<name>.series]``)
PRESET, DRIVETRAIN_FILE, LOAD_RECORD = "preset", "drivetrain file", "load record"
#: suffix of an FMU file
FMU_SUFFIX = ".fmu"
#: hand-written documentation pages, one per FMU (``<name>.html``) and ``hosts.html`` shared by all
DOC_CONTENT_DIR = Path(__file__).with_name("doc_content")

#: the record model of an FMU built from a co-simulation drivetrain and the rotor-speed defaults
ModelOf = Callable[[Drivetrain, WindParameters], dict[str, Any]]


class UnknownFmu(KeyError):
    """An FMU name the registry does not declare (the message lists the known ones)."""

    def __str__(self) -> str:
        return str(self.args[0])


def _wind_model(drivetrain: Drivetrain, wind: WindParameters) -> dict[str, Any]:
    return {"wind": describe(wind)}


def _gearbox_model(drivetrain: Drivetrain, wind: WindParameters) -> dict[str, Any]:
    return {"drivetrain": describe(drivetrain), "rotor_speed_rad_s": wind.mean_speed_rad_s}


def _generator_model(drivetrain: Drivetrain, wind: WindParameters) -> dict[str, Any]:
    if drivetrain.generator is None:
        raise ValueError("a GeneratorRotor FMU needs a drivetrain with a generator")
    return {"generator": describe(drivetrain.generator), "initial_speed_rad_s": drivetrain.ratio * wind.mean_speed_rad_s}


def _rotor_model(drivetrain: Drivetrain, wind: WindParameters) -> dict[str, Any]:
    return {"rotor": describe(RotorParameters()), "initial_speed_rad_s": wind.mean_speed_rad_s}


def _controller_model(drivetrain: Drivetrain, wind: WindParameters) -> dict[str, Any]:
    return {"controller": describe(TorqueLawParameters()), "initial_speed_rad_s": drivetrain.ratio * wind.mean_speed_rad_s}


def _series_cross_check(model: dict[str, Any]) -> CrossCheckCase:
    """A load record's FMU: its first second of record (or the whole record if shorter), from the record's start."""
    series = model["series"]
    start = float(series["start_s"]) - float(series["time_offset_s"])
    stop = min(start + 1.0, float(series["end_s"]) - float(series["time_offset_s"]))
    return CrossCheckCase(stop, start_time=start)


@dataclass(frozen=True)
class FmuKind:
    """One FMU this project builds.

    Attributes
    ----------
    name : str
        Model name, also the slave class's name and the FMU file's stem.
    slave_module : str
        Module under ``fmus.slaves`` that defines the slave class.
    role : str
        What the component is in a drivetrain (:data:`fmus.slaves.record.ROLES`), declared in its record.
    built_from : tuple of str
        :data:`PRESET`, :data:`DRIVETRAIN_FILE`, :data:`LOAD_RECORD`: what the FMU can be built from.
    model_of : callable or None
        ``(drivetrain, wind) -> record model`` for an FMU built from a preset or a drivetrain file
        (None: its model comes with what it is built from, a load record's samples).
    init_note : str
        Its part of the initialisation order (documentation).
    cross_check : CrossCheckCase or callable
        The stand-alone run whose inputs and outputs the FMU carries (:mod:`fmus.cross_check`), or
        ``model -> CrossCheckCase`` where it depends on what the FMU is built from (a load record).
    """

    name: str
    slave_module: str
    role: str
    built_from: tuple[str, ...]
    model_of: ModelOf | None
    init_note: str
    cross_check: CrossCheckCase | Callable[[dict[str, Any]], CrossCheckCase] | None = None

    def cross_check_case(self, model: dict[str, Any]) -> CrossCheckCase | None:
        """The cross-check run of this FMU built from ``model``."""
        return self.cross_check(model) if callable(self.cross_check) else self.cross_check

    @property
    def file_name(self) -> str:
        """``<name>.fmu``: the file the build writes and a scenario names."""
        return self.name + FMU_SUFFIX

    @property
    def documentation_page(self) -> Path:
        """The hand-written part of its ``documentation/index.html`` (what it is, its equations)."""
        return DOC_CONTENT_DIR / f"{self.name}.html"

    def slave_class(self) -> type:
        """The pythonfmu slave class (imports its module)."""
        return getattr(importlib.import_module(f"fmus.slaves.{self.slave_module}"), self.name)

    def model(self, drivetrain: Drivetrain, wind: WindParameters | None = None) -> dict[str, Any]:
        """The record ``model`` of this FMU built from a co-simulation drivetrain (with generator and output shaft).

        Parameters
        ----------
        drivetrain : Drivetrain
            The gearbox structure and defaults, with the generator (its inertia and counter torque
            are the GeneratorRotor's defaults).
        wind : WindParameters, optional
            The rotor-speed defaults (default: the paper's, Sec. 4.2); its mean speed sets the
            Gearbox's input start values and the generator's initial speed (``ratio * omega0``).

        Raises
        ------
        ValueError
            The FMU is not built from a drivetrain (a TimeSeriesSource), or it needs a generator the drivetrain lacks.
        """
        if self.model_of is None:
            raise ValueError(f"FMU {self.name} is not built from a drivetrain: its model comes with its "
                             + " or ".join(self.built_from))
        return self.model_of(drivetrain, wind or WindParameters())


#: every FMU of the project, by model name
KINDS: dict[str, FmuKind] = {k.name: k for k in (
    FmuKind("WindSource", "wind_source", WIND_SOURCE, (PRESET,), _wind_model,
            "it has no inputs and comes first; its outputs at the start time depend on its parameters only, "
            "and after each step they are the values at t + h computed in the FMU.",
            CrossCheckCase(2.0)),
    FmuKind("Gearbox", "gearbox", GEARBOX, (PRESET, DRIVETRAIN_FILE), _gearbox_model,
            "set omega_rotor and phi_rotor before reading omega_out; omega_gen and phi_gen come from the "
            "GeneratorRotor (or, standalone, must advance consistently with each other: angles held while speeds "
            "are not zero twist the shafts).",
            # a 1 % generator-speed pulse of 20 ms (the angles integrate the speeds): the drivetrain rings
            CrossCheckCase(0.5, ramps=(Ramp("omega_gen", (0.1, 0.11, 0.12), (1.0, 1.01, 1.0)),),
                           integrals=(("phi_rotor", "omega_rotor"), ("phi_gen", "omega_gen")))),
    FmuKind("GeneratorRotor", "generator_rotor", GENERATOR, (PRESET, DRIVETRAIN_FILE), _generator_model,
            "set initial_speed (the Gearbox's omega_out) and initial_angle before "
            "fmi2ExitInitializationMode; its input shaft_torque is used from the first fmi2DoStep on.",
            # balanced at the default counter torque, then a 10 % shaft-torque pulse
            CrossCheckCase(0.5, ramps=(Ramp("shaft_torque", (0.0, 0.1, 0.15, 0.2), values=(25400.0, 25400.0, 27940.0,
                                                                                         25400.0)),))),
    FmuKind("Rotor", "rotor", ROTOR, (PRESET,), _rotor_model,
            "set initial_speed (and aero_torque, which sets a main shaft's initial twist) before "
            "fmi2ExitInitializationMode; its outputs omega and phi drive the Gearbox's omega_rotor and phi_rotor, "
            "the Gearbox's torque_rotor comes back as gearbox_torque from the first fmi2DoStep on.",
            # balanced at the paper's rated rotor torque, then a 10 % aerodynamic-torque pulse
            CrossCheckCase(0.5, ramps=(Ramp("gearbox_torque", (0.0,), values=(2.54e6,)),
                                       Ramp("aero_torque", (0.0, 0.1, 0.15, 0.2), values=(2.54e6, 2.54e6, 2.794e6,
                                                                                        2.54e6))))),
    FmuKind("TorqueController", "torque_controller", TORQUE_CONTROLLER, (PRESET,), _controller_model,
            "set generator_speed (the generator's initial speed) and pitch before "
            "fmi2ExitInitializationMode: they set the filter state and the initial torque.",
            CrossCheckCase(1.0, ramps=(Ramp("generator_speed", (0.1, 0.3), (1.0, 1.05)),))),
    FmuKind("TimeSeriesSource", "time_series_source", TIME_SERIES, (LOAD_RECORD,), None,
            "it has no inputs and comes first; set time_offset so that the run lies inside the "
            "record (out_of_record = error refuses a start outside it in fmi2ExitInitializationMode).",
            _series_cross_check),
)}
#: every model name, in declaration order
FMU_NAMES = tuple(KINDS)


def kind(name: str) -> FmuKind:
    """The FMU called ``name``.

    Raises
    ------
    UnknownFmu
        Naming the FMUs there are.
    """
    try:
        return KINDS[name]
    except (KeyError, TypeError):
        raise UnknownFmu(f"unknown FMU {name!r}: expected one of {', '.join(FMU_NAMES)}") from None


def built_from(source: str) -> tuple[FmuKind, ...]:
    """The FMUs that can be built from ``source`` (:data:`PRESET`, :data:`DRIVETRAIN_FILE`, :data:`LOAD_RECORD`)."""
    return tuple(k for k in KINDS.values() if source in k.built_from)


def names_built_from(source: str) -> tuple[str, ...]:
    """Model names of :func:`built_from`."""
    return tuple(k.name for k in built_from(source))


def with_role(role: str) -> FmuKind | None:
    """The project FMU of ``role`` (None if no FMU of the project has it)."""
    return next((k for k in KINDS.values() if k.role == role), None)


def of_file(path: str | Path) -> FmuKind | None:
    """The project FMU a scenario's ``fmu = "<name>.fmu"`` names (None: a path to an FMU of someone else).

    A project FMU is named by its bare file name, with no folder: that is how a scenario asks for an
    FMU this project builds (:attr:`FmuKind.file_name`).
    """
    path = Path(path)
    if path.parent != Path(".") or path.suffix != FMU_SUFFIX:
        return None
    return KINDS.get(path.stem)


def drivetrain_of_preset(preset: str) -> Drivetrain:
    """The co-simulation drivetrain of a preset name (:func:`components.model.presets.cosim_preset`).

    Raises
    ------
    ValueError
        Naming the presets there are.
    """
    if preset not in PRESETS:
        raise ValueError(f"unknown preset {preset!r}: expected one of {', '.join(PRESETS)}")
    return cosim_preset(preset)
