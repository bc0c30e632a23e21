"""Real loads in (issue 15): the packaged OpenFAST scenarios built and run, and the new FMUs through fmpy.

Figures (printed with ``-s``): generator speed against the record (openfast-dlc11), mean stage forces
against the quasi-static T / (n r_b), rotor speed against RotSpeed (openfast-dlc11-torque), contact loss
through the grid loss.
"""

from __future__ import annotations

import math
import shutil

import fmpy
import numpy as np
import pytest
from fmpy.util import write_csv

from components.model.time_series import Interpolant
from components.model.torque_controller import TorqueLawParameters, law_torque_nm
from fmus.cross_check import compare, read_reference
from orchestrator.provision.project_fmus import ensure_fmus
from orchestrator.provision.series_fmus import ensure_series_fmu
from orchestrator.cosim.system import resolve_system
from orchestrator.errors import ScenarioError
from orchestrator.inputs.overrides import apply_parameters
from orchestrator.inputs.scenario_file import find_scenario, load_scenario
from orchestrator.run.runner import run_scenario
from tests.helpers.openfast_data import openfast_file

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def fmu_home(tmp_path_factory):
    return tmp_path_factory.mktemp("openfast-fmus")


def run(name: str, fmu_home, out, **simulation):
    openfast_file("DLC2.3_1.out")  # skips without the shared data
    scenario = load_scenario(find_scenario(name))
    if simulation:
        scenario = scenario.with_simulation(**simulation)
    paths = ensure_fmus(scenario, fmu_home)
    system = resolve_system(scenario, fmu_paths=paths)
    return system, run_scenario(system, out, handle_sigint=False)


def column(outcome, name):
    return outcome.column(name)


def test_dlc11_generator_speed_follows_the_record_and_stage_forces_are_quasi_static(fmu_home, tmp_path):
    system, report = run("openfast-dlc11", fmu_home, tmp_path)
    o, s = report.outcome, report.summary
    assert o.complete
    row = next(r for r in s["recorded_comparison"] if r["quantity"] == "generator_speed")
    print(f"\nopenfast-dlc11 generator speed vs GenSpeed over {row['window_s']} s: RMS {row['rms_difference']:.4g} rad/s "
          f"({100 * row['rms_difference_relative']:.3g} %), max {row['max_difference']:.4g} rad/s "
          f"({100 * row['max_difference_relative']:.3g} %)")
    assert row["rms_difference_relative"] < 2e-3 and row["max_difference_relative"] < 1e-2
    assert (tmp_path / "recorded_vs_simulated.png").is_file()
    # quasi-static stage forces of the recorded torque: the generator torque GenTq plus the generator inertia
    # times the recorded GenSpeed's mean acceleration, referred through the ideal ratios
    t = o.time_s
    w0, w1 = system.scenario.simulation.window_s
    m = (t >= w0) & (t <= w1)
    gen_speed = column(o, "loads.generator_speed")
    mean_accel = (gen_speed[m][-1] - gen_speed[m][0]) / (t[m][-1] - t[m][0])
    hss_torque = column(o, "loads.generator_torque")[m].mean() + 534.116 * mean_accel
    base_r = {"planetary1": 0.24 * math.cos(math.radians(20)) * 20 / 20, "planetary2": 0.189 * math.cos(math.radians(20)),
              "high_speed": 0.48 * math.cos(math.radians(20))}
    sun1_torque = 96 * hss_torque / 6  # carrier torque / stage-1 ratio
    expected = {"planetary1.F_sp[1]": sun1_torque / (3 * base_r["planetary1"]),
                "planetary2.F_sp[1]": sun1_torque / 5.333333333333333 / (3 * base_r["planetary2"]),
                "high_speed.F_mesh": sun1_torque / 5.333333333333333 / base_r["high_speed"]}
    for mesh, force in expected.items():
        mean = column(o, f"gearbox.{mesh}")[m].mean()
        print(f"  mean {mesh} {mean:.6g} N vs quasi-static {force:.6g} N: {100 * (mean / force - 1):+.3f} %")
        assert mean == pytest.approx(force, rel=5e-3)


def test_dlc11_torque_rotor_speed_within_one_percent_and_controller_on_its_curve(fmu_home, tmp_path):
    system, report = run("openfast-dlc11-torque", fmu_home, tmp_path)
    o, s = report.outcome, report.summary
    assert o.complete
    row = next(r for r in s["recorded_comparison"] if r["quantity"] == "rotor_speed")
    print(f"\nopenfast-dlc11-torque rotor speed vs RotSpeed: RMS {100 * row['rms_difference_relative']:.3g} %, "
          f"max {100 * row['max_difference_relative']:.3g} %")
    assert row["rms_difference_relative"] < 0.01
    law = TorqueLawParameters(region3_mode="constant_torque", rated_torque_nm=43664.0)
    demand = column(o, "controller.generator_torque")
    filtered = column(o, "controller.filtered_speed")
    pitch = column(o, "loads.pitch")
    on_curve = [law_torque_nm(law, w, p) for w, p in zip(filtered, pitch)]
    assert demand == pytest.approx(on_curve, rel=1e-12)  # region 3 by pitch throughout: never rate limited here


@pytest.fixture(scope="module")
def torque_driven(fmu_home):
    """openfast-dlc11-torque with the module's FMUs: ``resolve(values) -> resolved system`` (nothing instantiated)."""
    openfast_file("DLC2.3_1.out")
    base = load_scenario(find_scenario("openfast-dlc11-torque"))
    paths = ensure_fmus(base, fmu_home)
    return lambda values=None: resolve_system(apply_parameters(base, values or {}), fmu_paths=paths)


def test_new_fmus_publish_the_bounds_of_their_own_validation(torque_driven):
    system = torque_driven()
    for comp, name, minimum in (("rotor", "inertia", 1e-30), ("controller", "max_rate", 1e-30),
                                ("controller", "region3_mode", 0), ("loads", "out_of_record", 0),
                                ("loads", "time_offset", -1e30)):
        iface = system.interfaces[comp]
        assert iface.record["bounds"][name]["min"] == minimum, (comp, name)
        assert iface.variables[name].minimum == minimum, (comp, name)  # modelDescription min/max
    assert system.interfaces["controller"].record["bounds"]["region3_mode"]["max"] == 1


@pytest.mark.parametrize("values, key, expected", [
    ({"rotor.inertia": -1.0}, "components.rotor.parameters.inertia", "> 0 (within [1e-30, 1e+30])"),
    ({"rotor.shaft_damping": 1e300}, "components.rotor.parameters.shaft_damping", ">= 0 (at most 1e+30)"),
    ({"controller.region3_mode": 2}, "components.controller.parameters.region3_mode",
     "0 = constant_power, 1 = constant_torque"),
    ({"controller.filter_corner": 0.0}, "components.controller.parameters.filter_corner", "> 0 (within"),
    ({"loads.out_of_record": 2}, "components.loads.parameters.out_of_record", "0 = hold, 1 = error"),
    ({"loads.time_offset": 1e300}, "components.loads.parameters.time_offset", "a finite real number"),
    # coupled: within their bounds, refused by the model's own check on the host
    ({"controller.region2_start": 200.0}, "components.controller.parameters.region2_start",
     "cut_in_speed (70.1622) < region2_start < rated_speed"),
    ({"rotor.shaft_stiffness": 1e9}, "components.rotor.parameters.carrier_inertia", "> 0 with a main shaft"),
    ({"loads.time_offset": 1e5}, "components.loads.parameters.time_offset",
     "an offset keeping the run [0, 10] s inside the record"),
])
def test_values_the_new_fmus_refuse_are_refused_before_instantiation(torque_driven, values, key, expected):
    with pytest.raises(ScenarioError) as info:
        torque_driven(values)
    assert info.value.key == key and str(info.value.expected).startswith(expected), str(info.value)


def test_controller_fmu_torque_lies_on_the_configured_curve(fmu_home, tmp_path):
    from fmus.build import build_fmu

    path = build_fmu("TorqueController", tmp_path).path
    speeds = np.linspace(60.0, 130.0, 141)
    signal = np.array([(i * 0.01, w) for i, w in enumerate(speeds)], dtype=[("time", float), ("generator_speed", float)])
    result = fmpy.simulate_fmu(str(path), start_time=0.0, stop_time=1.4, step_size=0.01, output_interval=0.01,
                               input=signal, start_values={"max_rate": 1e12, "filter_corner": 1e9},
                               output=["generator_torque", "filtered_speed"])
    law = TorqueLawParameters(max_rate_nm_s=1e12, filter_corner_rad_s=1e9)
    for w, torque in zip(result["filtered_speed"][1:], result["generator_torque"][1:]):
        assert torque == pytest.approx(law_torque_nm(law, w), rel=1e-9, abs=1e-6)
    assert {round(w) for w in result["filtered_speed"]} >= {65, 80, 100, 120, 125}  # every region visited


def test_grid_loss_runs_through_the_event_and_counts_contact_loss(fmu_home, tmp_path):
    system, report = run("openfast-grid-loss", fmu_home, tmp_path, start_s=55.0, stop_s=72.0, window_s=(56.0, 72.0))
    o, s = report.outcome, report.summary
    assert o.complete and o.error is None
    cl = s["contact_loss"]
    print(f"\nopenfast-grid-loss 55-72 s: {cl['total_separations']} separations, {cl['total_flank_changes']} flank changes, "
          f"{len(cl['meshes_with_contact_loss'])} meshes")
    assert cl["total_flank_changes"] > 0 and set(cl["meshes"]) == set(cl["meshes_with_contact_loss"])
    for png in ("recorded_vs_simulated.png", "contact_loss_counts.png", "contact_forces.png"):
        assert (tmp_path / png).is_file()
    gen_torque = column(o, "generator.generator_torque")
    assert gen_torque[o.time_s > 60.1].max() == 0.0 and gen_torque[o.time_s < 60.0].min() > 2e4


def test_time_series_fmu_is_exact_at_record_points_interpolates_between_and_is_self_contained(tmp_path):
    record = tmp_path / "record.csv"
    t = np.round(np.arange(0.0, 1.0001, 0.05), 10)
    speed = 12.0 + np.sin(7 * t) + (t > 0.5)
    record.write_text("Time [s],RotSpeed [rpm],GenTq [kN-m]\n"
                      + "".join(f"{float(a)!r},{float(b)!r},{float(c)!r}\n" for a, b, c in zip(t, speed, 40 + t)))
    scenario_file = tmp_path / "s.toml"
    scenario_file.write_text("""
[simulation]
stop = 1.0
step = 0.01
[components.loads]
fmu = "TimeSeriesSource.fmu"
[components.loads.series]
record = "record.csv"
[[components.loads.series.channels]]
channel = "RotSpeed"
output = "w"
angle = "phi"
[[components.loads.series.channels]]
channel = "GenTq"
interpolation = "linear"
""")
    spec = load_scenario(scenario_file).component("loads").series
    fmu = ensure_series_fmu(spec, tmp_path / "fmus")
    record.unlink()
    moved = tmp_path / "elsewhere" / "TimeSeriesSource.fmu"
    moved.parent.mkdir()
    shutil.move(fmu, moved)
    fine = fmpy.simulate_fmu(str(moved), stop_time=1.0, step_size=0.01, output_interval=0.01)
    rpm = math.pi / 30
    at_points = fine[::5]
    assert np.array_equal(at_points["time"].round(10), t)
    assert at_points["w"] == pytest.approx(speed * rpm, rel=1e-14)  # every sample exactly (to round-off)
    assert at_points["GenTq"] == pytest.approx((40 + t) * 1e3, rel=1e-14)
    f = Interpolant(t, speed * rpm, "pchip")
    assert fine["w"] == pytest.approx([f.value(x) for x in fine["time"]], rel=1e-13)
    assert fine["phi"] == pytest.approx([f.integral(x) for x in fine["time"]], rel=1e-12, abs=1e-14)
    # it carries its own cross-check (fmus.cross_check): the record's first second, which a host's run meets
    model, ref, opts = read_reference(moved)
    assert (opts["StartTime"], opts["StopTime"]) == (0.0, 1.0) and list(ref.dtype.names) == ["time", "w", "phi", "GenTq"]
    host = fmpy.simulate_fmu(str(moved), stop_time=1.0, step_size=opts["StepSize"], output_interval=opts["StepSize"])
    write_csv(tmp_path / "host.csv", host)
    assert compare(moved, tmp_path / "host.csv").passed


def test_build_validate_and_export_ssp_with_the_new_fmus(fmu_home, tmp_path, capsys):
    import zipfile

    from orchestrator.commands.cli import main as dtcosim

    openfast_file("DLC1.1_0_NREL5MW_OC3_spar_2.outb")
    assert dtcosim(["build", "--scenario", "openfast-dlc11-torque", "--out", str(fmu_home)]) == 0
    built = sorted(fmu_home.rglob("*.fmu"))
    assert {p.name for p in built} >= {"TimeSeriesSource.fmu", "Rotor.fmu", "TorqueController.fmu"}
    assert dtcosim(["validate", *map(str, built)]) == 0
    ssp = tmp_path / "torque.ssp"
    assert dtcosim(["export-ssp", "openfast-dlc11-torque", "--fmu-dir", str(fmu_home), "--out", str(ssp)]) == 0
    with zipfile.ZipFile(ssp) as zf:
        assert {"resources/TimeSeriesSource.fmu", "resources/Rotor.fmu", "resources/TorqueController.fmu"} <= set(zf.namelist())
    capsys.readouterr()
    assert dtcosim(["run", str(ssp), "--stop", "0.2", "--out", str(tmp_path / "ssp-run"), "--no-plots"]) == 0
