"""What each FMU tells a foreign host: documentation/index.html, resources/requirements.txt, the description."""

from __future__ import annotations

import zipfile
from importlib import metadata

import pytest
from fmpy import read_model_description

from fmus.build import PRESET_FMU_NAMES, drivetrain_of_preset
from fmus.documentation import VARIABLE_TABLE_ID
from fmus.parameter_ranges import INPUT_RANGE, OUTPUT_RANGE, accepted_ranges
from fmus.registry import kind
from fmus.requirements import read_from_fmu
from fmus.validation import check_fmu
from orchestrator.commands.cli import main as dtcosim
from tests.helpers.html_tables import tables

FMU_NAMES = ("WindSource", "Gearbox", "GeneratorRotor")
SECTIONS = ("component", "equations", "variables", "initialisation", "errors", "hosts", "platforms")


def page(path) -> str:
    with zipfile.ZipFile(path) as archive:
        return archive.read("documentation/index.html").decode("utf-8")


@pytest.mark.parametrize("name", FMU_NAMES)
def test_archive_carries_documentation_and_requirements(fmu_path, name):
    with zipfile.ZipFile(fmu_path(name)) as archive:
        names = set(archive.namelist())
        requirements = archive.read("resources/requirements.txt").decode()
    assert {"documentation/index.html", "resources/requirements.txt"} <= names
    assert "# requires-python: >=3.11,<3.12" in requirements
    assert any(line.startswith("numpy>=") for line in requirements.splitlines())



@pytest.mark.parametrize("name", FMU_NAMES)
def test_html_variable_table_matches_the_model_description(fmu_path, name):
    rows = tables(page(fmu_path(name)))[0][VARIABLE_TABLE_ID]
    md = {v.name: v for v in read_model_description(str(fmu_path(name))).modelVariables}
    assert sorted(r["name"] for r in rows) == sorted(md)  # every variable, once
    for row in rows:
        v = md[row["name"]]
        assert int(row["vr"]) == v.valueReference, v.name
        assert (row["causality"], row["type"]) == (v.causality, v.type), v.name
        assert row["unit"] == (v.unit or "-"), v.name
        assert v.description.startswith(row["description"]), v.name
        if v.causality == "output":
            assert row["default"] == "" and v.start is None, v.name
        elif v.type == "Real":
            assert float(row["default"]) == float(v.start), v.name  # exact: both are repr of one double
        elif v.type == "Integer":
            assert int(row["default"]) == int(v.start), v.name
        else:
            assert row["default"] == str(v.start).lower(), v.name


@pytest.mark.parametrize("name, variable, expected", [
    ("WindSource", "sigma", "> 0 (within [1e-30, 1e+30])"),
    ("WindSource", "n_harmonics", "an integer within [1, 100000]"),
    ("WindSource", "seed", "an integer >= 0 (at most 2147483647, an FMI Integer)"),
    ("WindSource", "amplitude", "0 = variance, 1 = paper"),
    ("Gearbox", "stage1.k0", "> 0 (within [1e-30, 1e+30])"),
    ("Gearbox", "stage2.exponent", "within [1, 3]"),
    ("Gearbox", "shaft3.damping", ">= 0 (at most 1e+30)"),
    ("Gearbox", "omega_rotor", INPUT_RANGE),
    ("Gearbox", "shaft_torque", OUTPUT_RANGE),
    ("Gearbox", "extrapolate_inputs", "false, true"),
    ("GeneratorRotor", "inertia", "> 0 (within [1e-30, 1e+30])"),
    ("GeneratorRotor", "event1.kind", "0 = none, 1 = torque_step, 2 = grid_fault, 3 = emergency_stop"),
])
def test_ranges_are_what_the_validation_demands(fmu_path, name, variable, expected):
    assert accepted_ranges(name, kind(name).model(drivetrain_of_preset("table6")))[variable] == expected
    row = next(r for r in tables(page(fmu_path(name)))[0][VARIABLE_TABLE_ID] if r["name"] == variable)
    assert row["range"] == expected


@pytest.mark.parametrize("name", FMU_NAMES)
def test_page_has_every_section_the_requirements_and_the_platforms(fmu_path, name):
    text = page(fmu_path(name))
    found, ids = tables(text)
    assert set(SECTIONS) <= set(ids)
    req = read_from_fmu(fmu_path(name))
    rows = {r["what"]: r for r in found["requirements-table"]}
    assert rows["Python (CPython)"]["requirement"] == req.python_specifier
    assert rows["numpy"]["requirement"] == f"numpy{req.package('numpy').specifier[len('numpy'):]}"
    assert rows["numpy"]["tested with"] == metadata.version("numpy")
    assert "LD_PRELOAD" not in text and "DTCOSIM_FMU_LIBPYTHON" in text and "python.txt" in text
    for host in ("fmpy", "libcosim", "ecos", "Simulink", "Dymola"):
        assert host in text
    with zipfile.ZipFile(fmu_path(name)) as archive:
        carried = sorted({n.split("/")[1] for n in archive.namelist() if n.startswith("binaries/")})
    platforms = {r["platform"]: r for r in found["platforms-table"]}
    assert sorted(platforms) == carried == ["linux64", "win64"]
    assert platforms["linux64"]["tested"].startswith("yes")
    assert platforms["win64"]["tested"].startswith("no")
    assert "http" not in text and "<script" not in text  # self-contained


@pytest.mark.parametrize("name", FMU_NAMES)
def test_description_states_the_requirements(fmu_path, name):
    md = read_model_description(str(fmu_path(name)))
    assert read_from_fmu(fmu_path(name)).summary() in md.description
    assert "resources/requirements.txt" in md.description


def test_equations_carry_the_papers_numbers(fmu_path):
    gearbox = page(fmu_path("Gearbox"))
    for number in ("(1)", "(2)", "(3)", "(4)"):
        assert number in gearbox
    assert "eq. 5-10" in gearbox and "Eq. 11" in gearbox
    wind = page(fmu_path("WindSource"))
    assert "(13)" in wind and "(14)" in wind


def _strip(src, dst, member):
    with zipfile.ZipFile(src) as a, zipfile.ZipFile(dst, "w", zipfile.ZIP_DEFLATED) as b:
        for info in a.infolist():
            if info.filename != member:
                b.writestr(info, a.read(info))


@pytest.mark.parametrize("member, problem", [
    ("documentation/index.html", "has no documentation/index.html"),
    ("resources/requirements.txt", "declares no requirements"),
])
def test_validation_requires_the_declarations(fmu_path, tmp_path, member, problem):
    stripped = tmp_path / "WindSource.fmu"
    _strip(fmu_path("WindSource"), stripped, member)
    assert any(problem in p for p in check_fmu(stripped))


def test_cli_validate_checks_this_environment(fmu_dir, capsys):
    assert dtcosim(["validate", str(fmu_dir)]) == 0
    out = capsys.readouterr().out
    assert out.count("this environment has it") == len(PRESET_FMU_NAMES)
    assert "requires Python >=3.11,<3.12 with numpy>=" in out
