"""The ratings of a load-case set: ``[gear_rating]`` (ISO 6336) and ``[bearing_life]`` (ISO 281), validated.

A load-case file may give (every key optional; ``docs/lifetime.md`` has them in full)::

    [gear_rating]
    material = "case-carburised"         # a named material, or one of [gear_rating.materials]
    beyond_knee = "decline"              # or "endurance" (the S-N curves beyond their knee)
    factors = { K_Hbeta = 1.25 }         # any ISO 6336 factor (components.analysis.gear_rating.GearFactors)
    [gear_rating.stages.stage1]          # per stage: material, factors, and per member (sun, planet, ring,
    factors = { K_Hbeta = 1.3 }          # drive, driven) profile_shift, Y_F, Y_S, Y_B, Y_M, Z_BD
    gears = { sun = { profile_shift = 0.2 } }
    [gear_rating.materials.my-steel]     # stresses in MPa
    sigma_Hlim = 1300.0
    sigma_Flim = 430.0

    [bearing_life]
    reliability = 90.0                   # % (ISO 281 Table 12)
    a_iso = 1.0                          # or kappa, e_C and C_u [N] (ISO 281 9.3.3)
    [bearing_life.bearings.planet_bearing_1]
    kappa = 1.5
    e_C = 0.5
    C_u = 6.0e4

The checks that need the gearbox (stage and bearing names) are made when the set is prepared
(:mod:`orchestrator.study.ratings`), also before anything runs. Stresses are given in MPa and
``Z_E`` in sqrt(MPa) (the units of ISO 6336); everything else is SI.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Annotated, Any, Literal, Mapping

from pydantic import Field

from components.analysis.bearing_life import LifeModification
from components.analysis.gear_rating import BEYOND_KNEE, MATERIALS, GearFactors, GearInputs, GearMaterial
from components.errors import ParameterError

from ..frozen_map import FrozenMap
from .schema import Table

MPA = 1.0e6
#: the members of a stage a gear may be named by
MEMBERS = ("sun", "planet", "ring", "drive", "driven")
_FACTORS = tuple(f.name for f in fields(GearFactors))
_Point = Annotated[list[Annotated[float, Field(gt=0)]], Field(min_length=2, max_length=2)]


class _MaterialTable(Table):
    sigma_Hlim: float = Field(gt=0, description="a contact endurance limit > 0 [MPa]")
    sigma_Flim: float = Field(gt=0, description="a root endurance limit > 0 [MPa]")
    E: float = Field(206.0e3, gt=0, description="a Young's modulus > 0 [MPa]")
    nu: float = Field(0.3, ge=0, lt=0.5, description="a Poisson ratio in [0, 0.5)")
    Y_ST: float = Field(2.0, gt=0, description="a stress correction factor of the test gear > 0")
    Z_NT: list[_Point] | None = Field(None, min_length=2, description="[[cycles, factor], ...] pairs (Z_NT)")
    Y_NT: list[_Point] | None = Field(None, min_length=2, description="[[cycles, factor], ...] pairs (Y_NT)")


class _GearTable(Table):
    profile_shift: float = Field(0.0, ge=-1, le=2, description="a profile shift x in [-1, 2]")
    Y_F: float | None = Field(None, gt=0, description="a form factor > 0")
    Y_S: float | None = Field(None, gt=0, description="a stress correction factor > 0")
    Y_B: float = Field(1.0, gt=0, description="a rim thickness factor > 0")
    Y_M: float | None = Field(None, gt=0, le=1, description="a mean stress factor in (0, 1]")
    Z_BD: float | None = Field(None, ge=1, description="a single pair tooth contact factor >= 1")


class _StageTable(Table):
    material: str | None = Field(None, description="a material name")
    factors: dict[str, float] = Field(default_factory=dict, description="a table of ISO 6336 factors")
    gears: dict[Literal[MEMBERS], _GearTable] = Field(default_factory=dict,
                                                      description="a table per member: sun, planet, ring, drive, driven")


class GearRatingTable(Table):
    """``[gear_rating]``."""

    enabled: bool = Field(True, description="true or false")
    material: str = Field("case-carburised", description="a material name")
    beyond_knee: Literal[BEYOND_KNEE] = "decline"
    factors: dict[str, float] = Field(default_factory=dict, description="a table of ISO 6336 factors")
    stages: dict[str, _StageTable] = Field(default_factory=dict, description="a table per stage")
    materials: dict[str, _MaterialTable] = Field(default_factory=dict, description="a table per material")


class _BearingTable(Table):
    reliability: float | None = Field(None, ge=90, lt=100, description="a reliability [%] of ISO 281 Table 12")
    a_iso: float | None = Field(None, gt=0, le=50, description="a life modification factor in (0, 50]")
    kappa: float | None = Field(None, ge=0.1, description="a viscosity ratio >= 0.1")
    e_C: float | None = Field(None, ge=0, le=1, description="a contamination factor in [0, 1]")
    C_u: float | None = Field(None, gt=0, description="a fatigue load limit > 0 [N]")


class BearingLifeTable(_BearingTable):
    """``[bearing_life]``."""

    bearings: dict[str, _BearingTable] = Field(default_factory=dict, description="a table per bearing")


@dataclass(frozen=True)
class StageRating:
    """A stage's rating inputs: its material (a name) and factors, and per member its gear inputs."""

    material: str
    factors: GearFactors
    gears: Mapping[str, GearInputs] = field(default_factory=dict)


@dataclass(frozen=True)
class GearRatingOptions:
    """``[gear_rating]`` validated: every stage not listed gets the defaults.

    Attributes
    ----------
    enabled : bool
    material : str
        The default material's name (a key of :attr:`materials`).
    beyond_knee : str
    factors : GearFactors
        The default factors.
    stages : mapping of str -> StageRating
        Overrides per stage name (checked against the gearbox when the set is prepared).
    materials : mapping of str -> GearMaterial
        The named materials (:data:`components.analysis.gear_rating.MATERIALS` and the file's).
    """

    enabled: bool = True
    material: str = "case-carburised"
    beyond_knee: str = "decline"
    factors: GearFactors = field(default_factory=GearFactors)
    stages: Mapping[str, StageRating] = field(default_factory=dict)
    materials: Mapping[str, GearMaterial] = field(default_factory=lambda: dict(MATERIALS))

    def stage(self, name: str) -> StageRating:
        """The rating inputs of a stage (its overrides, else the defaults)."""
        return self.stages.get(name) or StageRating(self.material, self.factors)

    def describe(self) -> str:
        """One line for reports."""
        return f"{self.materials[self.material].name}, S-N curves beyond the knee: {self.beyond_knee}"


@dataclass(frozen=True)
class BearingLifeOptions:
    """``[bearing_life]`` validated: the default life modification and one per bearing name."""

    default: LifeModification = field(default_factory=LifeModification)
    bearings: Mapping[str, LifeModification] = field(default_factory=dict)

    def of(self, name: str) -> LifeModification:
        """The life modification of a bearing."""
        return self.bearings.get(name, self.default)


def _factors(table: Mapping[str, float], base: GearFactors, key: str, error, src) -> GearFactors:
    for name, value in table.items():
        if name not in _FACTORS:
            from ..errors import suggestion

            raise error(f"{key}.{name}", value, f"an ISO 6336 factor{suggestion(name, _FACTORS)}: "
                        + ", ".join(_FACTORS), src)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
            raise error(f"{key}.{name}", value, "a number > 0", src)
    try:
        return base.updated(**{k: float(v) for k, v in table.items()})
    except ParameterError as exc:
        raise error(f"{key}.{exc.name}", exc.value, exc.expected, src) from None


def _material(name: str, tab: _MaterialTable, key: str, error, src) -> GearMaterial:
    default = GearMaterial()
    try:
        return GearMaterial(name, tab.sigma_Hlim * MPA, tab.sigma_Flim * MPA, tab.E * MPA, tab.nu,
                            tuple(tuple(p) for p in tab.Z_NT) if tab.Z_NT else default.contact_life,
                            tuple(tuple(p) for p in tab.Y_NT) if tab.Y_NT else default.bending_life, tab.Y_ST)
    except ParameterError as exc:
        what = exc.name.removeprefix("material.")
        what = {"cycles": "Z_NT", "factor": "Z_NT"}.get(what, what).split(".")[0]
        raise error(f"{key}.{what}", exc.value, exc.expected, src) from None


def gear_rating_options(tab: GearRatingTable | None, error, src: str | None) -> GearRatingOptions:
    """:class:`GearRatingOptions` of a validated ``[gear_rating]`` table (None: the defaults)."""
    if tab is None:
        return GearRatingOptions()
    materials = dict(MATERIALS)
    for name, m in tab.materials.items():
        materials[name] = _material(name, m, f"gear_rating.materials.{name}", error, src)

    def known(material: str, key: str) -> str:
        if material not in materials:
            from ..errors import suggestion

            raise error(key, material, f"a material: {', '.join(materials)}{suggestion(material, list(materials))}", src)
        return material

    material = known(tab.material, "gear_rating.material")
    factors = _factors(tab.factors, GearFactors(), "gear_rating.factors", error, src)
    stages = {}
    for name, st in tab.stages.items():
        key = f"gear_rating.stages.{name}"
        gears = {}
        for member, g in st.gears.items():
            try:
                gears[member] = GearInputs(g.profile_shift, g.Y_F, g.Y_S, g.Y_B, g.Y_M, g.Z_BD)
            except ParameterError as exc:
                raise error(f"{key}.gears.{member}.{exc.name}", exc.value, exc.expected, src) from None
        stages[name] = StageRating(known(st.material or material, f"{key}.material"),
                                   _factors(st.factors, factors, f"{key}.factors", error, src), FrozenMap(gears))
    return GearRatingOptions(tab.enabled, material, tab.beyond_knee, factors, FrozenMap(stages), FrozenMap(materials))


def _modification(tab: _BearingTable, base: LifeModification | None, key: str, error, src) -> LifeModification:
    values: dict[str, Any] = {}
    if base is not None:
        values = {"reliability_percent": base.reliability_percent, "a_iso": base.a_iso,
                  "viscosity_ratio": base.viscosity_ratio, "contamination_factor": base.contamination_factor,
                  "fatigue_load_limit_n": base.fatigue_load_limit_n}
        if tab.a_iso is not None:  # a bearing's a_iso replaces the default's kappa, e_C, C_u and the other way round
            values.update(viscosity_ratio=None, contamination_factor=None, fatigue_load_limit_n=None)
        if any(v is not None for v in (tab.kappa, tab.e_C, tab.C_u)):
            values["a_iso"] = None
    given = {"reliability_percent": tab.reliability, "a_iso": tab.a_iso, "viscosity_ratio": tab.kappa,
             "contamination_factor": tab.e_C, "fatigue_load_limit_n": tab.C_u}
    values.update({k: v for k, v in given.items() if v is not None})
    names = {"reliability_percent": "reliability", "viscosity_ratio": "kappa", "contamination_factor": "e_C",
             "fatigue_load_limit_n": "C_u"}
    try:
        return LifeModification(**values)
    except ParameterError as exc:
        name = names.get(exc.name, exc.name)
        raise error(f"{key}.{name}" if name in names.values() or name == "a_iso" else key, exc.value, exc.expected,
                    src) from None


def bearing_life_options(tab: BearingLifeTable | None, error, src: str | None) -> BearingLifeOptions:
    """:class:`BearingLifeOptions` of a validated ``[bearing_life]`` table (None: the defaults)."""
    if tab is None:
        return BearingLifeOptions()
    default = _modification(tab, None, "bearing_life", error, src)
    bearings = {name: _modification(b, default, f"bearing_life.bearings.{name}", error, src)
                for name, b in tab.bearings.items()}
    return BearingLifeOptions(default, FrozenMap(bearings))
