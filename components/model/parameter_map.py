"""Flat, named SI parameters <-> a structured :class:`Drivetrain`.

FMUs and scenario files address parameters by flat names such as
``stage1.planet_inertia`` or ``shaft3.stiffness``. This module is the single
mapping between those names and the frozen parameter dataclasses, used by the
Gearbox FMU (its parameters) and by the orchestrator (monolithic reference of
a scenario), so both always describe the same drivetrain.

The structure (number and kind of stages, planets per stage) comes from a
template drivetrain; every value can be overridden by name. Validation happens
when the dataclasses are rebuilt, so a bad value raises
:class:`~components.errors.ParameterError` naming the parameter.

Names, units and meaning
------------------------
Per planetary stage ``stageK``: ``sun_radius``, ``ring_radius``, ``module``,
``width`` [m]; ``sun_mass``, ``planet_mass`` [kg]; ``sun_inertia``,
``planet_inertia``, ``carrier_inertia`` [kg m^2] (carrier: extra inertia on top of
the planets' orbital inertia). Per parallel stage: ``drive_radius``,
``driven_radius``, ``module``, ``width`` [m]; ``drive_mass``, ``driven_mass``
[kg]; ``drive_inertia``, ``driven_inertia`` [kg m^2]. Mesh contact of every stage
(the sun-planet and ring-planet meshes of a planetary stage share one set while
their contact parameters are equal, as in the paper's presets; a stage whose two
meshes differ has them as ``stageK.sun_mesh.<name>`` and ``stageK.ring_mesh.<name>``
instead; :func:`mesh_prefixes`): ``k0`` [N/m^e], ``exponent`` [-], ``c0``
[N s/m^2], ``lambda`` [1/m], ``backlash`` [m] (normal), ``pressure_angle`` [rad],
``contact_law`` (0 = CFS, 1 = impact), ``impact_depth`` [m], ``impact_damping``
[N s/m] (negative: ``c0 * impact_depth``), ``contact_ratio`` [-],
``stiffness_variation`` [-]. Planet angles are structure (like the number of
planets), not parameters. Per shaft ``shaftK``: ``stiffness`` [N m/rad],
``damping`` [N m s/rad]. Generator: ``generator.inertia`` [kg m^2],
``generator.counter_torque`` [N m]. Without a generator: ``output_torque`` [N m].

Lateral-torsional stages (:mod:`components.model.bearings`) add per planetary stage ``carrier_mass``
[kg], ``sun_bearing_stiffness``, ``carrier_bearing_stiffness``, ``planet_bearing_stiffness`` [N/m]
and their ``..._damping`` [N s/m]; with a moving ring ``ring_mass`` [kg], ``ring_inertia`` [kg m^2],
``ring_support_stiffness`` [N/m], ``ring_support_damping`` [N s/m], ``ring_torsional_stiffness``
[N m/rad], ``ring_torsional_damping`` [N m s/rad]; per parallel stage ``drive_bearing_stiffness``,
``driven_bearing_stiffness`` and their damping. A stage with pin position errors has
``pin_error_radial[i]`` and ``pin_error_tangential[i]`` [m] per planet ``i`` (1-based); gravity
``gravity.acceleration`` [m/s^2] and ``gravity.shaft_tilt`` [rad]. Bearing types and load
ratings, the ring's presence and the line of centres are structure.

The WindSource and GeneratorRotor FMUs' parameters have flat names of their own
(:func:`wind_from_values`: ``omega0``, ``a``, ``sigma``,
``n_harmonics``, ``f_min``, ``f_max``, ``seed``, ``amplitude``;
:func:`generator_values` / :func:`generator_from_values`: ``inertia``,
``counter_torque`` and the load-event slots ``event{i}.kind`` (0 none, then
:data:`~components.model.generator.EVENT_KINDS` from 1), ``event{i}.start``,
``event{i}.duration``, ``event{i}.factor``). The FMUs and the physics view of a
scenario both use these functions, so they cannot disagree.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Mapping

from ..errors import ParameterError
from ..validation import choice_bounds
from .bearings import Bearing
from .contact import CONTACT_LAW_DESCRIPTIONS, CONTACT_LAWS, MeshContact
from .drivetrain import Drivetrain
from .generator import EVENT_KINDS, GeneratorParameters, LoadEvent
from .stages import PlanetaryStage, Shaft
from .wind import AMPLITUDE_CONVENTIONS, WindParameters

#: WindSource FMU parameter -> WindParameters field
WIND_FIELDS = {
    "omega0": "mean_speed_rad_s", "a": "spectrum_level", "sigma": "sigma_rad_s", "n_harmonics": "n_harmonics",
    "f_min": "f_min_rad_s", "f_max": "f_max_rad_s", "seed": "seed",
}
#: GeneratorRotor FMU parameter -> GeneratorParameters field
GENERATOR_FIELDS = {"inertia": "inertia_kgm2", "counter_torque": "counter_torque_nm"}
#: load-event slots of the GeneratorRotor FMU
N_EVENT_SLOTS = 4
#: ``event{i}.kind`` codes: 0 = no event, then the event kinds
EVENT_KIND_CODES = ("none",) + EVENT_KINDS
#: slot parameter -> LoadEvent field
_SLOT_FIELDS = {"start": "start_s", "duration": "duration_s", "factor": "factor"}

UNITS: dict[str, str] = {
    "sun_radius": "m", "ring_radius": "m", "drive_radius": "m", "driven_radius": "m", "module": "m", "width": "m",
    "sun_mass": "kg", "planet_mass": "kg", "drive_mass": "kg", "driven_mass": "kg",
    "sun_inertia": "kg.m2", "planet_inertia": "kg.m2", "carrier_inertia": "kg.m2",
    "drive_inertia": "kg.m2", "driven_inertia": "kg.m2",
    "k0": "N/m^e", "exponent": "1", "c0": "N.s/m2", "lambda": "1/m", "backlash": "m", "pressure_angle": "rad",
    "contact_law": "1", "impact_depth": "m", "impact_damping": "N.s/m", "contact_ratio": "1",
    "stiffness_variation": "1", "stiffness": "N.m/rad", "damping": "N.m.s/rad", "inertia": "kg.m2",
    "counter_torque": "N.m", "output_torque": "N.m",
    "carrier_mass": "kg", "ring_mass": "kg", "ring_inertia": "kg.m2", "ring_torsional_stiffness": "N.m/rad",
    "ring_torsional_damping": "N.m.s/rad", "pin_error_radial": "m", "pin_error_tangential": "m",
    "acceleration": "m/s2", "shaft_tilt": "rad",
    **{f"{member}_{kind}": unit for member in ("sun_bearing", "carrier_bearing", "planet_bearing", "ring_support",
                                               "drive_bearing", "driven_bearing")
       for kind, unit in (("stiffness", "N/m"), ("damping", "N.s/m"))},
}

DESCRIPTIONS: dict[str, str] = {
    "sun_radius": "sun pitch radius", "ring_radius": "ring pitch radius", "drive_radius": "drive-gear pitch radius",
    "driven_radius": "driven-gear pitch radius", "module": "gear module", "width": "face width",
    "sun_mass": "sun mass", "planet_mass": "mass of one planet", "drive_mass": "drive-gear mass",
    "driven_mass": "driven-gear mass", "sun_inertia": "sun polar inertia", "planet_inertia": "planet spin inertia",
    "carrier_inertia": "carrier inertia in addition to the planets' orbital inertia",
    "drive_inertia": "drive-gear inertia", "driven_inertia": "driven-gear inertia",
    "k0": "Hertzian contact stiffness k0 (eq. 2)", "exponent": "contact force exponent e",
    "c0": "contact damping c0, damping = c0 |delta_BL| (eq. 2, 9)", "lambda": "backlash regularisation factor (eq. 4)",
    "backlash": "normal backlash j_n", "pressure_angle": "pressure angle", "contact_law": ", ".join(f"{code} = {law}" for code, law in enumerate(CONTACT_LAW_DESCRIPTIONS)),
    "impact_depth": "penetration d_max of full impact damping", "impact_damping": "impact damping c_max (< 0: c0 * d_max)",
    "contact_ratio": "contact ratio (time-varying stiffness)", "stiffness_variation": "relative mesh-stiffness variation (0: off)",
    "stiffness": "torsional stiffness", "damping": "torsional damping", "inertia": "rotor inertia",
    "counter_torque": "generator counter torque", "output_torque": "counter torque on the output gear",
    "carrier_mass": "carrier mass (its translation)", "ring_mass": "ring mass", "ring_inertia": "ring polar inertia",
    "ring_torsional_stiffness": "torsional stiffness of the ring's support",
    "ring_torsional_damping": "torsional damping of the ring's support",
    "pin_error_radial": "radial position error of the planet's pin", "pin_error_tangential":
    "tangential position error of the planet's pin (in the direction of normal rotation)",
    "acceleration": "gravity", "shaft_tilt": "rotor shaft tilt",
    **{f"{member}_{kind}": f"radial {kind} of the {member.replace('_', ' ')}"
       for member in ("sun_bearing", "carrier_bearing", "planet_bearing", "ring_support", "drive_bearing",
                      "driven_bearing") for kind in ("stiffness", "damping")},
}

_MESH_FIELDS = {
    "k0": "stiffness", "exponent": "exponent", "c0": "damping", "lambda": "regularisation",
    "backlash": "backlash_normal_m", "pressure_angle": "pressure_angle_rad", "impact_depth": "impact_depth_m",
    "contact_ratio": "contact_ratio", "stiffness_variation": "stiffness_variation",
}
_PLANETARY_FIELDS = {
    "sun_radius": "sun_radius_m", "ring_radius": "ring_radius_m", "module": "module_m", "width": "width_m",
    "sun_mass": "sun_mass_kg", "planet_mass": "planet_mass_kg", "sun_inertia": "sun_inertia_kgm2",
    "planet_inertia": "planet_inertia_kgm2", "carrier_inertia": "carrier_inertia_kgm2",
}
_PARALLEL_FIELDS = {
    "drive_radius": "drive_radius_m", "driven_radius": "driven_radius_m", "module": "module_m", "width": "width_m",
    "drive_mass": "drive_mass_kg", "driven_mass": "driven_mass_kg", "drive_inertia": "drive_inertia_kgm2",
    "driven_inertia": "driven_inertia_kgm2",
}


#: parameter field -> the field of the same prefix holding the exponent e of its unit (k0 [N/m^e])
UNIT_EXPONENTS: dict[str, str] = {"k0": "exponent"}


def unit_exponent_parameter(name: str) -> str:
    """The flat parameter whose value is the ``e`` of ``name``'s unit (``stage1.k0`` -> ``stage1.exponent``), or ``""``."""
    prefix, _, field = name.rpartition(".")
    other = UNIT_EXPONENTS.get(field)
    return "" if other is None else (f"{prefix}.{other}" if prefix else other)


def _field(name: str) -> str:
    """The field of a flat name: its last part without an index (``stage1.pin_error_radial[2]`` -> ``pin_error_radial``)."""
    return name.rsplit(".", 1)[-1].split("[", 1)[0]


def unit_of_parameter(name: str) -> str:
    """Unit string of a flat parameter name (``"N/m^e"`` has the exponent e)."""
    return UNITS.get(_field(name), "1")


def description_of_parameter(name: str) -> str:
    """Short description of a flat parameter name."""
    return DESCRIPTIONS.get(_field(name), name)


def _mesh_values(prefix: str, mesh: MeshContact) -> dict[str, float]:
    out = {f"{prefix}.{k}": float(getattr(mesh, f)) for k, f in _MESH_FIELDS.items()}
    out[f"{prefix}.contact_law"] = float(CONTACT_LAWS.index(mesh.law))
    out[f"{prefix}.impact_damping"] = -1.0 if mesh.impact_damping is None else float(mesh.impact_damping)
    return out


def mesh_prefixes(stage) -> dict[str, str]:
    """Flat-name prefix of each mesh field of a stage: ``{"mesh": "stage3"}`` for a parallel stage;
    ``{"sun_mesh": "stage1", "ring_mesh": "stage1"}`` for a planetary stage whose two meshes are equal
    (one shared set of names), else ``{"sun_mesh": "stage1.sun_mesh", "ring_mesh": "stage1.ring_mesh"}``."""
    if not isinstance(stage, PlanetaryStage):
        return {"mesh": stage.name}
    if stage.sun_mesh == stage.ring_mesh:
        return {"sun_mesh": stage.name, "ring_mesh": stage.name}
    return {"sun_mesh": f"{stage.name}.sun_mesh", "ring_mesh": f"{stage.name}.ring_mesh"}


def _bearings(stage) -> dict[str, str]:
    """Flat-name member -> the lateral table's field of each bearing of a lateral stage (``{}`` torsional)."""
    lat = stage.lateral
    if lat is None:
        return {}
    if isinstance(stage, PlanetaryStage):
        return {"sun_bearing": "sun_bearing", "carrier_bearing": "carrier_bearing", "planet_bearing": "planet_bearing"}
    return {"drive_bearing": "drive_bearing", "driven_bearing": "driven_bearing"}


def _lateral_values(st) -> dict[str, float]:
    """The flat values of a stage's lateral model and pin errors (module docstring)."""
    out: dict[str, float] = {}
    lat = st.lateral
    for member, field_name in _bearings(st).items():
        b = getattr(lat, field_name)
        out[f"{st.name}.{member}_stiffness"] = b.stiffness_n_per_m
        out[f"{st.name}.{member}_damping"] = b.damping_ns_per_m
    if isinstance(st, PlanetaryStage):
        if lat is not None:
            out[f"{st.name}.carrier_mass"] = lat.carrier_mass_kg
            if lat.ring is not None:
                r = lat.ring
                out.update({f"{st.name}.ring_mass": r.mass_kg, f"{st.name}.ring_inertia": r.inertia_kgm2,
                            f"{st.name}.ring_support_stiffness": r.bearing.stiffness_n_per_m,
                            f"{st.name}.ring_support_damping": r.bearing.damping_ns_per_m,
                            f"{st.name}.ring_torsional_stiffness": r.torsional_stiffness_nm_per_rad,
                            f"{st.name}.ring_torsional_damping": r.torsional_damping_nms_per_rad})
        for i, (radial, tangential) in enumerate(st.pin_errors_m or ()):
            out[f"{st.name}.pin_error_radial[{i + 1}]"] = radial
            out[f"{st.name}.pin_error_tangential[{i + 1}]"] = tangential
    return out


def _lateral_changes(st, values: Mapping[str, float]) -> dict:
    """The stage's ``lateral`` and ``pin_errors_m`` with the given flat values (unchanged where none is given)."""
    changes: dict = {}
    lat = st.lateral
    get = lambda key, default: values.get(f"{st.name}.{key}", default)  # noqa: E731

    def bearing(member: str, b: Bearing) -> Bearing:
        return replace(b, stiffness_n_per_m=get(f"{member}_stiffness", b.stiffness_n_per_m),
                       damping_ns_per_m=get(f"{member}_damping", b.damping_ns_per_m))

    if lat is not None:
        lat_changes = {f: bearing(member, getattr(lat, f)) for member, f in _bearings(st).items()}
        if isinstance(st, PlanetaryStage):
            lat_changes["carrier_mass_kg"] = get("carrier_mass", lat.carrier_mass_kg)
            if lat.ring is not None:
                r = lat.ring
                lat_changes["ring"] = replace(
                    r, mass_kg=get("ring_mass", r.mass_kg), inertia_kgm2=get("ring_inertia", r.inertia_kgm2),
                    bearing=bearing("ring_support", r.bearing),
                    torsional_stiffness_nm_per_rad=get("ring_torsional_stiffness", r.torsional_stiffness_nm_per_rad),
                    torsional_damping_nms_per_rad=get("ring_torsional_damping", r.torsional_damping_nms_per_rad))
        changes["lateral"] = replace(lat, **lat_changes)
    if isinstance(st, PlanetaryStage) and st.pin_errors_m is not None:
        changes["pin_errors_m"] = tuple(
            (get(f"pin_error_radial[{i + 1}]", r), get(f"pin_error_tangential[{i + 1}]", t))
            for i, (r, t) in enumerate(st.pin_errors_m))
    return changes


def flatten(drivetrain: Drivetrain) -> dict[str, float]:
    """All parameter values of a drivetrain by flat name (SI units)."""
    out: dict[str, float] = {}
    for st in drivetrain.stages:
        fields = _PLANETARY_FIELDS if isinstance(st, PlanetaryStage) else _PARALLEL_FIELDS
        out.update({f"{st.name}.{k}": float(getattr(st, f)) for k, f in fields.items()})
        for field_name, prefix in mesh_prefixes(st).items():
            out.update(_mesh_values(prefix, getattr(st, field_name)))
        out.update(_lateral_values(st))
    if drivetrain.gravity is not None:
        out["gravity.acceleration"] = drivetrain.gravity.acceleration_m_s2
        out["gravity.shaft_tilt"] = drivetrain.gravity.shaft_tilt_rad
    for sh in drivetrain.all_shafts:
        out[f"{sh.name}.stiffness"] = sh.stiffness_nm_per_rad
        out[f"{sh.name}.damping"] = sh.damping_nms_per_rad
    if drivetrain.generator is not None:
        out["generator.inertia"] = drivetrain.generator.inertia_kgm2
        out["generator.counter_torque"] = drivetrain.generator.counter_torque_nm
    else:
        out["output_torque"] = drivetrain.output_torque_nm
    return out


def _mesh_from(prefix: str, mesh: MeshContact, values: Mapping[str, float]) -> MeshContact:
    changes = {f: values[f"{prefix}.{k}"] for k, f in _MESH_FIELDS.items() if f"{prefix}.{k}" in values}
    key = f"{prefix}.contact_law"
    if key in values:
        code = values[key]
        if not (isinstance(code, (int, float)) and not isinstance(code, bool) and float(code).is_integer()
                and 0 <= int(code) < len(CONTACT_LAWS)):
            raise ParameterError(key, code, "0 (CFS) or 1 (impact)", choice_bounds(CONTACT_LAWS, "0 (CFS) or 1 (impact)"))
        changes["law"] = CONTACT_LAWS[int(code)]
    key = f"{prefix}.impact_damping"
    if key in values:
        v = values[key]
        changes["impact_damping"] = None if (isinstance(v, (int, float)) and not math.isnan(v) and v < 0) else v
    try:
        return replace(mesh, **changes)
    except ParameterError as exc:  # re-raise under the flat name
        flat = next((f"{prefix}.{k}" for k, f in _MESH_FIELDS.items() if exc.name in (f, k)), f"{prefix}.{exc.name}")
        raise ParameterError(flat, exc.value, exc.expected, exc.bounds) from None


def unflatten(template: Drivetrain, values: Mapping[str, float]) -> Drivetrain:
    """A drivetrain with the structure of ``template`` and the given values.

    Parameters
    ----------
    template : Drivetrain
        Supplies the structure and every value not given.
    values : mapping of str -> float
        Flat names (see module docstring); unknown names raise ParameterError.

    Returns
    -------
    Drivetrain
        Validated; a bad value raises ParameterError naming the flat parameter.
    """
    known = flatten(template)
    for name in values:
        if name not in known:
            raise ParameterError(name, values[name], "a parameter of this drivetrain (see components.model.parameter_map)")
    stages = []
    for st in template.stages:
        fields = _PLANETARY_FIELDS if isinstance(st, PlanetaryStage) else _PARALLEL_FIELDS
        changes = {f: values[f"{st.name}.{k}"] for k, f in fields.items() if f"{st.name}.{k}" in values}
        for field_name, prefix in mesh_prefixes(st).items():
            changes[field_name] = _mesh_from(prefix, getattr(st, field_name), values)
        try:
            changes.update(_lateral_changes(st, values))
            stages.append(replace(st, **changes))
        except ParameterError as exc:
            local = exc.name.split(".", 1)[-1]
            flat = next((f"{st.name}.{k}" for k, f in fields.items() if f == local), f"{st.name}.{exc.name}")
            raise ParameterError(flat, exc.value, exc.expected, exc.bounds) from None

    def shaft(sh: Shaft) -> Shaft:
        try:
            return Shaft(
                sh.name,
                values.get(f"{sh.name}.stiffness", sh.stiffness_nm_per_rad),
                values.get(f"{sh.name}.damping", sh.damping_nms_per_rad),
            )
        except ParameterError as exc:
            raise ParameterError(exc.name.replace("_nm_per_rad", "").replace("_nms_per_rad", ""), exc.value, exc.expected, exc.bounds) from None

    shafts = tuple(shaft(sh) for sh in template.shafts)
    if template.gravity is not None:
        try:
            template = replace(template, gravity=replace(
                template.gravity, acceleration_m_s2=values.get("gravity.acceleration", template.gravity.acceleration_m_s2),
                shaft_tilt_rad=values.get("gravity.shaft_tilt", template.gravity.shaft_tilt_rad)))
        except ParameterError as exc:
            raise ParameterError(exc.name, exc.value, exc.expected, exc.bounds) from None
    if template.generator is not None:
        from .generator import GeneratorParameters

        gen = template.generator
        generator = GeneratorParameters(
            inertia_kgm2=values.get("generator.inertia", gen.inertia_kgm2),
            counter_torque_nm=values.get("generator.counter_torque", gen.counter_torque_nm),
            events=gen.events,
        )
        return replace(template, stages=tuple(stages), shafts=shafts, generator=generator, output_shaft=shaft(template.output_shaft))
    return replace(template, stages=tuple(stages), shafts=shafts, output_torque_nm=values.get("output_torque", template.output_torque_nm))


def _integer_code(name: str, value, choices: tuple[str, ...]) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not float(value).is_integer() \
            or not 0 <= int(value) < len(choices):
        text = ", ".join(f"{i} = {c}" for i, c in enumerate(choices))
        raise ParameterError(name, value, text, choice_bounds(choices, text))
    return int(value)


def wind_from_values(values: Mapping[str, float | int], template: WindParameters | None = None) -> WindParameters:
    """WindParameters from WindSource FMU parameter values (missing ones from ``template``).

    Raises
    ------
    ParameterError
        Naming the flat parameter (``seed``, ``amplitude``, ...).
    """
    template = template or WindParameters()
    changes = {f: values[k] for k, f in WIND_FIELDS.items() if k in values}
    if "amplitude" in values:
        changes["amplitude"] = AMPLITUDE_CONVENTIONS[_integer_code("amplitude", values["amplitude"], AMPLITUDE_CONVENTIONS)]
    try:
        return replace(template, **changes)
    except ParameterError as exc:  # WindParameters names them wind.<flat name>
        raise ParameterError(exc.name.removeprefix("wind."), exc.value, exc.expected, exc.bounds) from None


def generator_values(params: GeneratorParameters, n_slots: int = N_EVENT_SLOTS) -> dict[str, float | int]:
    """The GeneratorRotor FMU's parameter values of ``params`` by flat name, events in the first slots."""
    if len(params.events) > n_slots:
        raise ParameterError("generator.events", len(params.events), f"at most {n_slots} load events")
    out: dict[str, float | int] = {k: getattr(params, f) for k, f in GENERATOR_FIELDS.items()}
    for i in range(1, n_slots + 1):
        ev = params.events[i - 1] if i <= len(params.events) else None
        out[f"event{i}.kind"] = 0 if ev is None else EVENT_KIND_CODES.index(ev.kind)
        out[f"event{i}.start"] = 0.0 if ev is None else ev.start_s
        out[f"event{i}.duration"] = 1.0 if ev is None else ev.duration_s
        out[f"event{i}.factor"] = 1.0 if ev is None else ev.factor
    return out


def events_from_slots(values: Mapping[str, float | int], n_slots: int = N_EVENT_SLOTS) -> tuple[LoadEvent, ...]:
    """The load events of the slot parameters ``event{i}.*`` (kind 0: empty slot), in slot order.

    Raises
    ------
    ParameterError
        Naming the slot parameter (``event2.duration``, ...).
    """
    events = []
    for i in range(1, n_slots + 1):
        code = _integer_code(f"event{i}.kind", values.get(f"event{i}.kind", 0), EVENT_KIND_CODES)
        if code == 0:
            continue
        fields = {f: values[f"event{i}.{k}"] for k, f in _SLOT_FIELDS.items() if f"event{i}.{k}" in values}
        if "start_s" not in fields:
            raise ParameterError(f"event{i}.start", None, f"a start time [s] for the event of event{i}.kind = {code}")
        try:
            events.append(LoadEvent(kind=EVENT_KIND_CODES[code], **fields))
        except ParameterError as exc:  # LoadEvent names them event.<field>
            local = exc.name.removeprefix("event.")
            flat = next((k for k, f in _SLOT_FIELDS.items() if f == local), local)
            raise ParameterError(f"event{i}.{flat}", exc.value, exc.expected, exc.bounds) from None
    return tuple(events)


def generator_from_values(values: Mapping[str, float | int], template: GeneratorParameters | None = None,
                          n_slots: int = N_EVENT_SLOTS) -> GeneratorParameters:
    """GeneratorParameters from GeneratorRotor FMU parameter values (missing ones from ``template``).

    The events are those of the slots when any slot parameter is given, else the template's.
    """
    template = template or GeneratorParameters()
    changes: dict = {f: values[k] for k, f in GENERATOR_FIELDS.items() if k in values}
    if any(k.startswith("event") for k in values):
        changes["events"] = events_from_slots(values, n_slots)
    try:
        return replace(template, **changes)
    except ParameterError as exc:  # GeneratorParameters names them generator.<field>
        local = exc.name.removeprefix("generator.")
        flat = next((k for k, f in GENERATOR_FIELDS.items() if f == local), local)
        raise ParameterError(flat, exc.value, exc.expected, exc.bounds) from None
