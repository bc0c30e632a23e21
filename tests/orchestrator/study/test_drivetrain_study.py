"""A study varying entries of a drivetrain file: one FMU set per structure, exact flat values otherwise."""

from __future__ import annotations

import shutil

import pytest

from components.model.wind import RotorSpeedProcess, WindParameters
from components.reference.solver import simulate_monolithic
from orchestrator.inputs.drivetrain_entries import with_entries
from orchestrator.inputs.drivetrain_file import find_drivetrain, load_drivetrain_file
from orchestrator.inputs.study import StudyError
from orchestrator.inputs.study_file import load_study
from orchestrator.provision.folders import drivetrain_fmu_dir
from orchestrator.study.engine import PointTask, run_point
from orchestrator.study.prepare import prepare_study

pytestmark = pytest.mark.slow

STUDY = """
name = "grc-planets"
engine = "{engine}"
measures = ["gearbox.planetary.F_sp[1]:mean", "gearbox.intermediate.F_mesh:std"]

[base]
scenario = "grc-rated"

[simulation]
stop = 0.05
window = [0.0, 0.05]

[[axes]]
parameter = "gearbox.drivetrain.stages[0].planets"
values = [3, 4]

[[axes]]
parameter = "gearbox.drivetrain.stages[0].face_width"
values = [230.0, 250.0]
"""


@pytest.fixture(scope="module")
def fmu_home(tmp_path_factory, fmu_dir):
    home = tmp_path_factory.mktemp("study-fmus")
    shutil.copy(fmu_dir / "WindSource.fmu", home / "WindSource.fmu")
    return home


def run_all(prepared):
    return [run_point(prepared.payload, PointTask(k, p.index, dict(p.parameters)))
            for k, p in zip(prepared.keys, prepared.points)]


def test_monolithic_points_are_the_changed_files_exactly(fmu_home, write_study):
    prepared = prepare_study(load_study(write_study(STUDY.format(engine="monolithic"))), fmu_home)
    assert len(prepared.points) == 4 and len(prepared.payload.structures) == 2  # 3 and 4 planets
    assert set(prepared.identity["base"]["structures"]) == set(prepared.payload.structures)
    grc = load_drivetrain_file(find_drivetrain("grc-like"))
    records = run_all(prepared)
    assert all(r["status"] == "ok" for r in records), records
    for point, record in zip(prepared.points, records):
        planets = point.parameters["gearbox.drivetrain.stages[0].planets"]
        width = point.parameters["gearbox.drivetrain.stages[0].face_width"]
        spec = with_entries(grc, {"stages[0].planets": planets, "stages[0].face_width": width})
        # the same run outside the study: the changed file's drivetrain (its derived masses follow the width)
        wind = WindParameters(mean_speed_rad_s=2.303834612632515, seed=1)
        result = simulate_monolithic(spec.drivetrain, RotorSpeedProcess(wind), 0.05, output_interval_s=1e-3)
        expected = result.statistics((0.0, 0.05), ["planetary.F_sp[1]"])["planetary.F_sp[1]"]["mean"]
        assert record["measures"]["gearbox.planetary.F_sp[1]:mean"] == pytest.approx(expected, rel=1e-9)
    by_planets = {}
    for p, r in zip(prepared.points, records):
        by_planets.setdefault(p.parameters["gearbox.drivetrain.stages[0].planets"], []).append(
            r["measures"]["gearbox.planetary.F_sp[1]:mean"])
    assert min(by_planets[3]) > max(by_planets[4])  # four planets share the load


def test_cosim_builds_one_fmu_set_per_structure(fmu_home, write_study):
    prepared = prepare_study(load_study(write_study(STUDY.format(engine="cosim"))), fmu_home)
    structures = prepared.payload.structures
    assert len(structures) == 2
    grc = load_drivetrain_file(find_drivetrain("grc-like"))
    four = with_entries(grc, {"stages[0].planets": 4, "stages[0].face_width": 230.0})
    assert (drivetrain_fmu_dir(fmu_home, four) / "Gearbox.fmu").is_file()
    # the width changes no structure: those points set flat parameters of the same FMUs
    variants = prepared.payload.variants
    widths = [v for p, v in sorted(variants.items()) if v.parameters]
    assert all("gearbox.planetary.width" in v.parameters and "gearbox.planetary.sun_mass" in v.parameters
               for v in widths)
    records = run_all(prepared)
    assert all(r["status"] == "ok" for r in records), records
    four_planets = [r for p, r in zip(prepared.points, records)
                    if p.parameters["gearbox.drivetrain.stages[0].planets"] == 4]
    assert all(r["measures"]["gearbox.planetary.F_sp[1]:mean"] > 0 for r in four_planets)


@pytest.mark.parametrize("axis, values, pattern", [
    ("gearbox.drivetrain.stages[0].planets", "[5]", r"axes\[0\]\.values\[0\] \(gearbox\.drivetrain\.stages\[0\]\.planets\) "
                                                   r"= 5: .*\(stages\[0\]\.planets = 5: expected planets that do not "
                                                   r"overlap.*\(point 0\)$"),
    ("gearbox.drivetrain.stages[0].teeth.sunn", "[3]", r"an entry the drivetrain file has"),
    ("wind.drivetrain.stages[0].planets", "[3]", r"wind names none"),
])
def test_bad_file_entries_are_study_errors_before_anything_runs(fmu_home, write_study, axis, values, pattern):
    text = STUDY.format(engine="monolithic").split("[[axes]]")[0] + f'[[axes]]\nparameter = "{axis}"\nvalues = {values}\n'
    with pytest.raises(StudyError, match=pattern):
        prepare_study(load_study(write_study(text)), fmu_home)
