"""The monolithic reference of a scenario is read from the FMUs' records: a Gearbox built from Table 5."""

from __future__ import annotations

import json

import pytest

from components.model.parameter_map import flatten
from components.model.presets import cosim_preset
from fmus.build import build_all
from tests.helpers.scenarios import dtcosim


@pytest.fixture(scope="module")
def table5_fmu_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("table5-fmus")
    build_all(out, "table5")
    return out


@pytest.mark.slow
def test_compare_reference_reads_a_table5_gearbox_from_its_record(table5_fmu_dir, tmp_path):
    out = tmp_path / "out"
    # the paper scenario records stage2 and stage3 forces that a single planetary stage does not have:
    # record the gearbox's outputs by pattern instead
    scenario = tmp_path / "table5.toml"
    from orchestrator.inputs.scenario_file import find_scenario

    text = find_scenario("paper-60s").read_text()
    start = text.index("[record]")
    scenario.write_text(text[:start] + '[record]\nvariables = ["wind.omega", "gearbox.*", "generator.omega"]\n')
    proc = dtcosim("run", str(scenario), "--stop", "1", "--fmu-dir", str(table5_fmu_dir), "--out", str(out),
                   "--compare-reference", "--no-plots", "--no-build", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    comparison = summary["comparison"]
    assert comparison["built_from"]["gearbox"] == "preset table5"
    variables = comparison["variables"]
    assert "gearbox.stage1.F_sp[3]" in variables and not any(v.startswith("gearbox.stage2") for v in variables)
    for name in ("gearbox.stage1.F_sp[1]", "generator.omega", "wind.omega"):
        assert abs(variables[name]["relative_difference"]["mean"]) < 1e-4, (name, variables[name])
    # the reference used the structure of Table 5 (one planetary stage): the ratio is Table 5's
    ratio = summary["generator_vs_ideal"]["ratio"]
    assert ratio == pytest.approx(cosim_preset("table5").ratio, rel=1e-12)
    assert "stage2.k0" not in flatten(cosim_preset("table5"))
