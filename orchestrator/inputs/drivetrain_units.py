"""The units of a drivetrain file's numbers: a value with its unit, or a bare number in the ``[units]`` one.

Every dimensional entry of a drivetrain file may be written with its unit
(``backlash = "0.56 mm"``, ``inertia = "1.51e8 kg mm^2"``, ``k0 = "5e5 N/mm^1.5"``), converted to SI
by the registry of :mod:`orchestrator.inputs.quantities`. A bare number is in the unit the file's
``[units]`` table names for its dimension (:data:`DIMENSIONS`), or SI when the file has no
``[units]`` table. A ``[units]`` table names every dimension of the bare numbers the file uses, or
none: a file that names ``length = "mm"`` but not ``inertia`` would otherwise read its inertias in
kg m^2 without a word (and a table without ``length`` its module in metres). A contact stiffness's
unit has the force exponent e (k0 of F = k0 d^e is in N/m^e): ``"N/mm^e"`` takes each mesh's
exponent, ``"N/mm^1.5"`` fits only meshes with e = 1.5.
"""

from __future__ import annotations

from typing import Any

from .drivetrain_schema import DrivetrainFileError, UnitsTable
from .quantities import Given, UnitError, convert

#: ``[units]`` key -> SI unit of that dimension (the unit of the model's numbers)
DIMENSIONS: dict[str, str] = {
    "length": "m", "angle": "rad", "mass": "kg", "density": "kg/m3", "inertia": "kg.m2",
    "contact_stiffness": "N/m^e", "contact_damping": "N.s/m2", "regularisation": "1/m", "impact_damping": "N.s/m",
    "torsional_stiffness": "N.m/rad", "torsional_damping": "N.m.s/rad", "torque": "N.m", "speed": "rad/s",
    "bearing_stiffness": "N/m", "bearing_damping": "N.s/m", "force": "N", "acceleration": "m/s^2",
}


class FileUnits:
    """Conversions of a file's entries to SI, per its ``[units]`` table.

    Parameters
    ----------
    table : UnitsTable
    source : str, optional
        The file (error messages).

    Raises
    ------
    DrivetrainFileError
        A ``[units]`` entry that is no unit of its dimension (``units.<dimension>``).
    """

    def __init__(self, table: UnitsTable, source: str | None = None) -> None:
        self.source = source
        self.named = {k: v for k, v in table.model_dump().items() if v is not None}
        for dim, unit in self.named.items():
            if dim == "contact_stiffness":
                continue  # its dimension depends on each mesh's exponent: checked where it is used
            try:
                convert(1.0, unit, DIMENSIONS[dim])
            except UnitError as exc:
                raise DrivetrainFileError(f"units.{dim}", unit, exc.expected, source) from None

    def si(self, key: str, value: Given | Any, dimension: str, exponent: float | None = None) -> float:
        """The entry ``key`` (a :class:`Given` or a bare number) in SI.

        Raises
        ------
        DrivetrainFileError
            A unit of another dimension (naming ``key``), or a bare number of a dimension the
            ``[units]`` table leaves out although it names others.
        """
        given = value if isinstance(value, Given) else Given(float(value))
        target = DIMENSIONS[dimension]
        if given.unit is not None:
            try:
                return convert(given.magnitude, given.unit, target, exponent)
            except UnitError as exc:
                raise DrivetrainFileError(key, given.shown, f"a {dimension.replace('_', ' ')}: {exc.expected}",
                                          self.source) from None
        if not self.named:
            return given.magnitude  # no [units]: SI
        unit = self.named.get(dimension)
        if unit is None:
            raise DrivetrainFileError(key, given.magnitude, (
                f"a value with its unit (e.g. \"{given.magnitude:g} {target.replace('^e', '^1.5')}\"), or a "
                f"[units] entry {dimension} = \"...\": this file's [units] names {', '.join(self.named)}, and it "
                f"must name every dimension of the bare numbers the file uses, or none (then they are SI)"),
                self.source)
        try:
            return convert(given.magnitude, unit, target, exponent)
        except UnitError as exc:
            raise DrivetrainFileError(f"units.{dimension}", unit, exc.expected, self.source) from None

    def unit_of(self, dimension: str) -> str:
        """The unit of a bare number of ``dimension`` (messages)."""
        return self.named.get(dimension, DIMENSIONS[dimension])
