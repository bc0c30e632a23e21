"""Copies of dtcosim FMUs whose parameters start at given values (what `dtcosim export-ssp` archives)."""

from __future__ import annotations

import json
import zipfile

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from fmus.model_description import rewrite_archive
from fmus.start_values import StartValueError, write_with_start_values
from tests.helpers.fmu_hosts import DRIVERS, run_python
from tests.helpers.reference_fmus import reference_fmu

FATAL = 4


def start_values_of(path) -> dict:
    return {v.name: v.start for v in read_model_description(str(path)).modelVariables}


def values_after_instantiation(path, names: list[str]) -> dict:
    """What the FMU reports for ``names`` right after instantiation, nothing set (fmpy)."""
    md = read_model_description(str(path))
    refs = {v.name: (v.valueReference, v.type) for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(path)), modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="copy")
    fmu.instantiate(loggingOn=False)
    try:
        out = {}
        for name in names:
            vr, kind = refs[name]
            out[name] = {"Real": fmu.getReal, "Integer": fmu.getInteger, "Boolean": fmu.getBoolean}[kind]([vr])[0]
        return out
    finally:
        fmu.freeInstance()


@pytest.mark.parametrize("name, values", [
    ("GeneratorRotor", {"initial_speed": 168.79205544771082, "counter_torque": 23456.5}),
    ("WindSource", {"seed": 11, "omega0": 1.7}),
    ("Gearbox", {"stage1.k0": 1.25e9, "stage2.contact_law": 1}),
])
def test_a_copy_starts_at_the_values_in_its_description_and_in_the_slave(fmu_path, tmp_path, name, values):
    source = fmu_path(name)
    copy = write_with_start_values(source, tmp_path / f"{name}.fmu", values)
    starts = start_values_of(copy)
    for key, value in values.items():
        assert type(value)(starts[key]) == value  # modelDescription.xml, exactly
    assert values_after_instantiation(copy, list(values)) == values  # the slave applied them before any set
    original, changed = read_model_description(str(source)), read_model_description(str(copy))
    assert changed.guid != original.guid
    assert "Start values of 2 variables set by dtcosim export-ssp" in changed.description
    unchanged = {k: v for k, v in start_values_of(source).items() if k not in values}
    assert {k: starts[k] for k in unchanged} == unchanged  # nothing else moved
    with zipfile.ZipFile(source) as a, zipfile.ZipFile(copy) as b:
        assert sorted(a.namelist()) == sorted(b.namelist())
        assert json.loads(b.read("resources/dtcosim.json"))["start_values"] == values
        for member in a.namelist():
            if member not in ("modelDescription.xml", "resources/dtcosim.json"):
                assert a.read(member) == b.read(member), member


@pytest.mark.parametrize("values, match", [
    ({"no_such": 1.0}, "has no variable 'no_such'"),
    ({"omega": 1.0}, r"omega has causality 'output'; only a parameter or an input takes a start value"),
    ({"inertia": "heavy"}, r"inertia is a Real variable; its start value must be a number, not 'heavy'"),
    ({"event1.kind": 1.5}, r"event1.kind is an Integer variable; its start value must be a whole number, not 1.5"),
])
def test_a_value_the_fmu_cannot_take_is_refused_before_anything_is_written(fmu_path, tmp_path, values, match):
    target = tmp_path / "GeneratorRotor.fmu"
    with pytest.raises(StartValueError, match=match):
        write_with_start_values(fmu_path("GeneratorRotor"), target, values)
    assert not target.exists()


def test_another_tools_fmu_is_refused_naming_why(tmp_path):
    with pytest.raises(StartValueError, match=r"Dahlquist.fmu: not a dtcosim FMU \(no resources/dtcosim.json\)"):
        write_with_start_values(reference_fmu("Dahlquist"), tmp_path / "Dahlquist.fmu", {"k": 2.0})


@pytest.mark.slow
def test_a_record_start_value_for_no_parameter_gives_null_and_a_logged_message(fmu_path, this_python, tmp_path):
    fmu = tmp_path / "GeneratorRotor.fmu"
    fmu.write_bytes(fmu_path("GeneratorRotor").read_bytes())
    with zipfile.ZipFile(fmu) as archive:
        record = json.loads(archive.read("resources/dtcosim.json"))
    record["start_values"] = {"omega": 1.0}
    rewrite_archive(fmu, {"resources/dtcosim.json": json.dumps(record).encode()})
    proc = run_python(this_python, str(DRIVERS / "instantiate.py"), str(fmu), "1", "1")
    assert proc.returncode == 0, proc.stderr[-3000:]
    report = json.loads(proc.stdout.splitlines()[-1])
    assert report["attempts"][0]["ok"] is False
    assert any("start_values: 'omega' is not a parameter or input of this FMU" in m for _, m in report["messages"])
