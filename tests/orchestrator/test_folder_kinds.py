"""Results of a run and of a study never mix in one folder (issue 30.5).

``dtcosim run openfast-dlc11`` and ``dtcosim loads openfast-dlc11`` both wrote into
``results/openfast-dlc11/`` and left a mixed folder. Load sets and sweeps now default to
``results/loads/<set>/`` and ``results/sweeps/<study>/``, and a folder holding results of
another kind (or another study's journal) is refused before anything is written.
"""

from __future__ import annotations

import json

import pytest

from orchestrator.folder_kinds import held_results, mixing_problem
from orchestrator.inputs.study import StudyError
from orchestrator.run.run_folder import OutputFolderError, RunFolder
from orchestrator.study.sweep import check_study_folder
from tests.helpers.scenarios import dtcosim


def _run_folder(path, scenario="openfast-dlc11"):
    path.mkdir(parents=True)
    (path / "summary.json").write_text(json.dumps({"scenario": scenario, "status": "complete"}))
    return path


def _study_folder(path, study="openfast-dlc11"):
    path.mkdir(parents=True)
    (path / "journal.jsonl").write_text(json.dumps({"key": "k", "study": study, "status": "ok"}) + "\n")
    return path


def test_what_a_folder_holds(tmp_path):
    assert held_results(tmp_path) is None
    assert held_results(_run_folder(tmp_path / "r")) == ("run", "openfast-dlc11")
    assert held_results(_study_folder(tmp_path / "s", "shaft3-seeds")) == ("study", "shaft3-seeds")


def test_a_run_into_a_load_sets_folder_is_refused_naming_what_it_holds(tmp_path):
    folder = _study_folder(tmp_path / "set")
    with pytest.raises(OutputFolderError, match=r"--out = '.*set': expected a folder for a run; this one holds the "
                                                r"journal of a study or load set 'openfast-dlc11' \(journal\.jsonl\)"):
        RunFolder.check(folder)
    assert sorted(p.name for p in folder.iterdir()) == ["journal.jsonl"]  # nothing written


def test_a_load_set_into_a_runs_folder_or_another_studys_is_refused(tmp_path):
    with pytest.raises(StudyError, match=r"holds the results of a run 'openfast-dlc11' \(summary\.json\)"):
        check_study_folder(_run_folder(tmp_path / "run"), "openfast-dlc11")
    with pytest.raises(StudyError, match=r"for the study or load set 'paper-turbine'; this one holds the journal "
                                         r"of a study or load set 'openfast-dlc11'"):
        check_study_folder(_study_folder(tmp_path / "set"), "paper-turbine")
    check_study_folder(tmp_path / "set", "openfast-dlc11")  # its own journal: resumed
    assert mixing_problem(_run_folder(tmp_path / "other-run", "paper-60s"), "run") is None  # a run replaces a run


@pytest.mark.slow
def test_run_and_loads_of_one_name_go_to_different_folders(fmu_dir, tmp_path):
    run = dtcosim("run", "openfast-dlc11", "--fmu-dir", str(fmu_dir), "--check", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    loads = dtcosim("loads", "openfast-dlc11", "--fmu-dir", str(fmu_dir), "--check", cwd=tmp_path)
    assert loads.returncode == 0, loads.stderr
    assert "into results/loads/openfast-dlc11" in loads.stdout
    _run_folder(tmp_path / "mixed")
    refused = dtcosim("loads", "openfast-dlc11", "--fmu-dir", str(fmu_dir), "--check", "--out", "mixed", cwd=tmp_path)
    assert refused.returncode == 1 and "holds the results of a run" in refused.stderr and "Traceback" not in refused.stderr
