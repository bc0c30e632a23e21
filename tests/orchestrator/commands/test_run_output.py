"""What a new user sees: overridden runs in their own folder, the moved window as a warning, 80-column tables,
Fig. 17 with the analysis window and identical planet meshes drawn once."""

from __future__ import annotations

import numpy as np
import pytest

from orchestrator.commands.cli import main
from orchestrator.run.plots import symmetric_groups
from orchestrator.run.text_tables import fit_table


def test_a_run_with_overrides_writes_to_its_own_folder_and_says_so(fmu_dir, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["run", "--fmu-dir", str(fmu_dir), "--stop", "0.2", "--no-plots", "-q"]) == 0
    err = capsys.readouterr().err
    folders = [p.name for p in (tmp_path / "results").iterdir()]
    assert len(folders) == 1 and folders[0].startswith("paper-60s-") and len(folders[0]) == len("paper-60s-") + 8
    assert f"note: --stop 0.2 change the scenario: results go to results/{folders[0]}/ (results/paper-60s/ is for " \
           "the scenario as written" in err
    assert "warning: analysis window moved from [5, 60] s to [0, 0.2] s to fit the run [0, 0.2] s" in err
    # the gearbox <-> generator loop's deliberate one-step delay is the summary's and --check's, not every run's
    assert "one-step delay" not in err
    assert main(["run", "--fmu-dir", str(fmu_dir), "--check"]) == 0
    checked = capsys.readouterr()
    assert "  coupling: one-step delay on generator.omega -> gearbox.omega_gen" in checked.out, checked
    # the same overrides again: the same folder, and the replacement is said
    assert main(["run", "--fmu-dir", str(fmu_dir), "--stop", "0.2", "--no-plots", "-q"]) == 0
    assert f"note: replacing the previous run in results/{folders[0]}/ (scenario paper-60s, complete, started" \
           in capsys.readouterr().err
    assert [p.name for p in (tmp_path / "results").iterdir()] == folders


def test_the_paper_runs_output_fits_80_columns(paper_run):
    _, _, proc = paper_run
    lines = proc.stdout.splitlines()
    assert len(lines) > 30 and max(len(line) for line in lines) <= 80


def test_long_names_get_a_line_of_their_own_and_columns_never_touch():
    rows = [["short", "-1.2346e+07", "-4.5547e-20"], ["a." * 30 + "long_name", "1", "2"]]
    lines = fit_table(["variable", "mean", "min"], rows)
    assert max(map(len, lines)) <= 80
    assert lines[1].split() == ["short", "-1.2346e+07", "-4.5547e-20"]
    assert lines[2].strip() == "a." * 30 + "long_name" and lines[3].split() == ["1", "2"]


def test_identical_planet_meshes_are_merged_and_others_kept():
    t = np.linspace(0, 1, 50)
    f = np.sin(t)
    groups = symmetric_groups([("F_sp[1]", "sun_planet", f), ("F_sp[2]", "sun_planet", f.copy()),
                               ("F_rp[1]", "ring_planet", f.copy()), ("F_sp[3]", "sun_planet", f + 1e-3)])
    assert [(g[0], g[3]) for g in groups] == [("F_sp[1]", ["F_sp[2]"]), ("F_rp[1]", []), ("F_sp[3]", [])]


@pytest.mark.slow
def test_fig17_has_a_panel_over_the_analysis_window_and_says_the_planets_are_identical(paper_run):
    from PIL import Image

    out, summary, _ = paper_run
    image = Image.open(out / "contact_forces.png")
    width, height = image.size
    assert width > 1.5 * height  # two panels per stage: the whole run and the window


def test_the_statistics_list_signals_only(toy_scenario, tmp_path):
    """Issue 30.5: a recorded parameter is recorded, but it is no signal: the statistics leave it out."""
    import json

    from tests.helpers.scenarios import TOY_SCENARIO

    path = toy_scenario(TOY_SCENARIO.replace('variables = ["src.y"', 'variables = ["src.amplitude", "src.y"'))
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-plots", "-q"]) == 0
    statistics = json.loads((out / "summary.json").read_text())["statistics"]
    assert "src.y" in statistics and "int.x" in statistics and "src.amplitude" not in statistics
    assert "src.amplitude" in (out / "timeseries.csv").read_text().splitlines()[0]
