"""A drivetrain file's values judged by physics, each finding named by the file key it comes from.

The rules and their bounds are :mod:`components.analysis.plausibility` (backlash against module
and tooth thickness, module and face width against the gear size, masses and inertias against
the steel disc, mesh stiffness against ISO 6336-1), evaluated at the file's rating: its
``[operating_point]`` rotor speed and its generator's (or output's) counter torque. An
implausible value is a :class:`~orchestrator.inputs.drivetrain_schema.DrivetrainFileError` naming
the file, the key (``stages[1].face_width``), the value as written, the bound and its reason,
unless the file keeps it on purpose::

    [plausibility]
    allow = ["stage2.width", "stage2.sun_mass"]   # flat parameter names (the FMU's)

Each allowed name must be a parameter of the drivetrain (a typo is refused, not ignored); the
design table (``dtcosim drivetrain show``) lists every rule per stage, the allowed findings too.
"""

from __future__ import annotations

from typing import Any, Mapping, Sequence

from components.analysis.plausibility import RULES, Judgement, Rating, implausible, judge
from components.model.drivetrain import Drivetrain
from components.model.gear_geometry import GeometryCheck
from components.model.parameter_map import flatten

from ..errors import suggestion
from .drivetrain_schema import DrivetrainFileError


def split_path(path: str) -> list[str | int]:
    """``stages[1].teeth.ring`` -> ``["stages", 1, "teeth", "ring"]`` (ValueError: not a key path)."""
    parts: list[str | int] = []
    for piece in path.split("."):
        name, _, rest = piece.partition("[")
        if name:
            parts.append(name)
        while rest:
            index, _, rest = rest.partition("]")
            parts.append(int(index))
            rest = rest.lstrip("[")
    return parts


def entry_at(data: Mapping[str, Any], path: str) -> Any:
    """The entry of a parsed document at a key path, None if it has none."""
    node: Any = data
    try:
        for part in split_path(path):
            node = node[part]
    except (ValueError, KeyError, IndexError, TypeError):
        return None
    return node


def allow_hint(key: str, where: str) -> str:
    """How a deliberate study keeps an implausible value: ``[plausibility] allow = ["<key>"] <where>``."""
    return f'a deliberate value is kept by [plausibility] allow = ["{key}"] {where}'


def check_file(drivetrain: Drivetrain, rotor_speed_rad_s: float, allow: Sequence[str], file_keys: Mapping[str, str],
               data: Mapping[str, Any], source: str | None) -> tuple[Judgement, ...]:
    """Every judgement of the file's drivetrain at its rating; the first implausible value not allowed raises.

    Parameters
    ----------
    drivetrain : Drivetrain
    rotor_speed_rad_s : float
        The file's operating point (its rated rotor speed).
    allow : sequence of str
        ``[plausibility] allow``: flat parameter names.
    file_keys : mapping of str -> str
        Flat parameter name -> the file key its value comes from.
    data : mapping
        The parsed document (the value as written).
    source : str or None

    Raises
    ------
    DrivetrainFileError
        An allowed name that is no parameter of the drivetrain, or an implausible value.
    """
    names = flatten(drivetrain)
    for i, name in enumerate(allow):
        if name not in names:
            raise DrivetrainFileError(f"plausibility.allow[{i}]", name, "a parameter name of this drivetrain such as "
                                      f"{next(iter(names))}{suggestion(name, names)}", source)
    judgements = judge(drivetrain, Rating.of(drivetrain, rotor_speed_rad_s))
    bad = implausible(judgements, allow)
    if bad:
        j = bad[0]
        key = file_keys.get(j.key, j.key)
        written = entry_at(data, key)
        shown = written if isinstance(written, (int, float, str)) and not isinstance(written, bool) \
            else f"{j.in_si} (derived)"
        raise DrivetrainFileError(key, shown, f"{j.expected}; it is {j.in_si} in SI ({j.key}); "
                                  + allow_hint(j.key, "in this file"), source)
    return judgements


def plausibility_checks(judgements: Sequence[Judgement], allow: Sequence[str]) -> dict[str, tuple[GeometryCheck, ...]]:
    """Stage name -> one check per rule: passed, or not met with the allowed values named (the design table)."""
    out: dict[str, list[GeometryCheck]] = {}
    for stage in dict.fromkeys(j.key.split(".", 1)[0] for j in judgements):
        for rule in RULES:
            mine = [j for j in judgements if j.rule == rule.name and j.key.split(".", 1)[0] == stage]
            if not mine:
                continue
            failed = [j for j in mine if not j.passed]
            detail = "; ".join(dict.fromkeys(f"{j.key.split('.', 1)[1]} {j.value:.4g} {j.unit}, plausible {j.bound}"
                                             + (f" ({j.reason})" if failed else "") for j in failed or mine))
            if failed:
                detail = "allowed by [plausibility]: " + detail
            out.setdefault(stage, []).append(GeometryCheck(f"plausible {rule.title}", not failed, detail))
    return {k: tuple(v) for k, v in out.items()}
