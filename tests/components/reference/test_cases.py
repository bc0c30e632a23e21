"""The paper's cases with the monolithic reference solver (Tables 2, 4, 7; Fig. 10-11, 16)."""

import json

import numpy as np
import pytest

from components.reference.cases import CASES, TABLE7_PAPER, run_case
from orchestrator.commands.cli import main


@pytest.fixture(scope="module")
def table7():
    return run_case("table7")


def test_table2_parallel_stage_mean_force():
    _, stats = run_case("table2")
    assert stats["stage1.F_mesh"]["mean"] == pytest.approx(9.67e3, rel=0.01)


def test_table4_planetary_stage_force_sums():
    _, stats = run_case("table4")
    assert stats["stage1.sum_F_sp"]["mean"] == pytest.approx(9.66e3, rel=0.01)
    assert stats["stage1.sum_F_rp"]["mean"] == pytest.approx(9.66e3, rel=0.01)


def test_fig10_sine_drive_crosses_the_backlash():
    result, stats = run_case("sine")
    assert result.complete
    f = result["stage1.F_sp[1]"]
    assert f.max() > 10.0 and f.min() < -10.0  # both flanks carry load
    inside = np.abs(f) < 1.0
    assert 0.1 < inside.mean() < 0.99  # zero-force intervals inside the backlash
    edges = np.flatnonzero(np.diff(inside.astype(int)))
    assert edges.size >= 6  # repeated contact loss and re-contact
    assert stats["stage1.F_sp[1]"]["backlash_fraction"] == pytest.approx(inside.mean(), abs=1e-3)


def test_table7_means(table7, capsys):
    result, stats = table7
    assert result.complete
    for name, (mean, std) in TABLE7_PAPER.items():
        assert stats[name]["mean"] == pytest.approx(mean, rel=0.01), name
        with capsys.disabled():
            print(f"\n{name}: mean {stats[name]['mean']:.5g} (paper {mean:.5g}), std {stats[name]['std']:.5g} (paper {std:.5g})")


def test_fig16_generator_follows_ideal_gearbox(table7):
    result, stats = table7
    dev = stats["omega_gen_deviation"]
    assert max(abs(dev["min"]), abs(dev["max"])) < 0.01


def test_energy_audit_closes(table7):
    result, _ = table7
    e = result.energy
    assert e.input_work_j > 2e8  # ~4.3 MW for 60 s
    assert e.relative_residual < 0.005
    assert e.dissipated_j > 0


def test_monolithic_run_is_fast(table7):
    result, _ = table7
    assert result.info["rhs_calls"] < 50_000  # the benchmark tracks wall time; this guards against stiffness blow-ups


def test_reference_cli_json(capsys):
    assert main(["reference", "--case", "table2", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["case"] == "table2"
    assert set(out["statistics"]["stage1.F_mesh"]) == {"mean", "std", "min", "max"}
    assert out["wall_time_s"] > 0


def test_reference_cli_table7_names(capsys):
    assert main(["reference", "--case", "table7", "--json", "--t-end", "6"]) == 0
    stats = json.loads(capsys.readouterr().out)["statistics"]
    for k in (1, 2):
        for i in (1, 2, 3):
            assert f"stage{k}.F_sp[{i}]" in stats and f"stage{k}.F_rp[{i}]" in stats
    assert "stage3.F_mesh" in stats and "omega_gen" in stats


def test_all_cases_are_listed():
    assert set(CASES) == {"table2", "table4", "sine", "table7"}


def test_impact_law_stands_in_for_the_paper_cfa_on_table2():
    """Table 2 compares CFS with CAD contact (CFA, 9.68e3 N); the impact law of eq. 1 gives the same mean."""
    from components import units
    from components.model.presets import table3_parallel
    from components.model.wind import ConstantSpeed
    from components.reference.solver import simulate_monolithic

    dt = table3_parallel().with_meshes(law="impact")
    result = simulate_monolithic(dt, ConstantSpeed(units.rpm(5.0)), 1.0)
    assert result.complete
    mean = result.statistics((0.5, 1.0), ["stage1.F_mesh"])["stage1.F_mesh"]["mean"]
    assert mean == pytest.approx(9.68e3, rel=0.01)
    assert result.energy.relative_residual < 0.005


def test_backlash_shading_of_a_hand_made_force():
    """The shaded spans are exactly the runs of samples with |F| < 1 N (plots of runs and of reference cases)."""
    from orchestrator.plotting import new_figure, shade_inside_backlash

    def shaded(force):
        fig, (ax,) = new_figure()
        shade_inside_backlash(ax, np.arange(10.0), force, 1.0)
        return sorted((float(p.vertices[:, 0].min()), float(p.vertices[:, 0].max()))
                      for c in ax.collections for p in c.get_paths())

    force = np.array([0.0, 0.5, 5.0, 6.0, 0.2, -0.3, -4.0, 0.0, 0.0, 3.0])
    assert shaded(force) == [(0.0, 1.0), (4.0, 5.0), (7.0, 8.0)]
    assert shaded(np.full(10, 7.0)) == []
    assert shaded(np.zeros(10)) == [(0.0, 9.0)]


def test_reference_out_writes_series_summary_and_the_fig10_11_plot(tmp_path, capsys):
    from orchestrator.result_files import read_timeseries

    out = tmp_path / "sine"
    assert main(["reference", "--case", "sine", "--t-end", "0.4", "--out", str(out)]) == 0
    assert f"results in {out}/: timeseries.csv, summary.json, reference.png" in capsys.readouterr().out
    header, data = read_timeseries(out / "timeseries.csv")
    assert header[:4] == ["time [s]", "omega_rotor [rad/s]", "phi_rotor [rad]", "stage1.F_sp[1] [N]"]
    assert data.shape == (2001, len(header)) and data[-1, 0] == pytest.approx(0.4)
    # the same force as the in-process run, and both flanks inside 0.4 s
    force = data[:, header.index("stage1.F_sp[1] [N]")]
    assert force.min() < -1.0 and force.max() > 1.0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["case"] == "sine" and summary["complete"] is True
    assert summary["statistics"]["stage1.F_sp[1]"]["max"] == pytest.approx(force.max())
    assert (out / "reference.png").stat().st_size > 20_000
