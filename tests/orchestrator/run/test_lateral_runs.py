"""The lateral-torsional scenarios run through the FMUs: planet load sharing in summary.json (issue 33.3).

paper-60s (torsional) and paper-60s-lateral share the load equally: factor 1. paper-60s-pin-error moves the pin of
stage-1 planet 1 by 50 um: that planet carries more, by the static factor of benchmarks/load_sharing.py (1.0172 at
the rated load; the wind's fluctuation of the load moves it a little over the window), stage 2 stays at 1.
"""

from __future__ import annotations

import json

import pytest

from tests.helpers.scenarios import dtcosim

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def fmu_home(tmp_path_factory):
    return tmp_path_factory.mktemp("lateral-fmus")


def _run(name, home, tmp_path):
    out = tmp_path / name
    proc = dtcosim("run", name, "--out", str(out), "--no-plots", "-q", "--fmu-dir", str(home), cwd=tmp_path,
                   timeout=1800)
    assert proc.returncode == 0, proc.stderr
    return json.loads((out / "summary.json").read_text())


def test_the_torsional_paper_run_shares_the_load_equally(paper_run):
    _, summary, _ = paper_run
    stages = summary["load_sharing"]["stages"]
    assert set(stages) == {"gearbox.stage1", "gearbox.stage2"}
    for s in stages.values():
        assert s["factor"] == pytest.approx(1.0, abs=1e-12) and s["mean_factor"] == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("name, stage1, most_loaded", [("paper-60s-lateral", (1.0, 1e-9), None),
                                                       ("paper-60s-pin-error", (1.0172, 1e-3), 1)])
def test_lateral_runs_report_the_load_sharing_of_each_stage(name, stage1, most_loaded, fmu_home, tmp_path):
    summary = _run(name, fmu_home, tmp_path)
    stages = summary["load_sharing"]["stages"]
    factor, tolerance = stage1
    assert stages["gearbox.stage1"]["factor"] == pytest.approx(factor, abs=tolerance)
    assert stages["gearbox.stage2"]["factor"] == pytest.approx(1.0, abs=1e-6)
    if most_loaded is not None:
        shares = stages["gearbox.stage1"]["shares"]
        assert stages["gearbox.stage1"]["most_loaded_planet"] == most_loaded and shares[0] > 1.01 > max(shares[1:])
    # every bearing's force is an output (the scenarios record them)
    bearings = [k for k in summary["statistics"] if k.endswith(".F") and "_bearing" in k]
    assert len(bearings) == 12  # per planetary stage 3 planets, sun and carrier; the parallel stage's 2
