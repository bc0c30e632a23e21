"""Output folders never mix (issue 30 item 5): a run and a load set of one name go to different folders, and a
command refuses a folder that holds another command's results (or another study's journal)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from orchestrator.commands import cli
from orchestrator.commands.loads import default_out_dir, earlier_default_folder
from orchestrator.commands.scenario_options import default_out_dir as run_out_dir
from orchestrator.study.journal import Journal
from tests.helpers.studies import SMALL_HEAD, SMALL_TABLES

GRID = SMALL_HEAD + SMALL_TABLES + '[[axes]]\nparameter = "gearbox.R1"\nvalues = [8.0, 9.0]\n'


def test_a_run_and_a_load_set_of_one_name_go_to_different_folders():
    from orchestrator.inputs.scenario_file import find_scenario, load_scenario

    scenario = load_scenario(find_scenario("openfast-dlc11"))
    args = cli.build_parser(["run", "openfast-dlc11"]).parse_args(["run", "openfast-dlc11"])
    run_dir, _ = run_out_dir(scenario, args)
    assert run_dir == Path("results/openfast-dlc11")
    assert default_out_dir("openfast-dlc11") == Path("results/loads/openfast-dlc11")


def test_a_run_into_a_sweeps_or_load_sets_folder_is_refused(toy_scenario, tmp_path, capsys):
    out = tmp_path / "openfast-dlc11"
    with Journal(out / "journal.jsonl") as j:
        j.append({"key": "k", "status": "ok", "study": "openfast-dlc11"})
    assert cli.main(["run", str(toy_scenario()), "--out", str(out), "--no-build", "-q"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"dtcosim run: error: invalid command-line entry --out = '{out}': expected a folder without a "
                   "sweep's or load set's results (it holds the journal of 'openfast-dlc11', journal.jsonl: a run's "
                   "files beside it would mix two commands' results); choose another --out"]
    assert sorted(p.name for p in out.iterdir()) == ["journal.jsonl"]


@pytest.mark.parametrize("extra", [["--check"], ["--report"], ["--workers", "1"]])
def test_a_sweep_into_a_runs_folder_is_refused_before_anything_is_prepared(toy_scenario, write_study, tmp_path,
                                                                           capsys, extra):
    out = tmp_path / "run"
    assert cli.main(["run", str(toy_scenario()), "--out", str(out), "--no-build", "-q"]) == 0
    before = sorted(p.name for p in out.iterdir())
    capsys.readouterr()
    assert cli.main(["sweep", str(write_study(GRID)), "--out", str(out), "-q", *extra]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"dtcosim sweep: error: invalid command-line entry --out = '{out}': expected a folder without a "
                   "run's results (it holds the summary.json of a run of 'toy': the study's files beside it would "
                   "mix two commands' results); choose another --out"]
    assert sorted(p.name for p in out.iterdir()) == before


def test_a_sweep_into_another_studys_folder_is_refused(write_study, tmp_path, capsys):
    out = tmp_path / "other"
    out.mkdir()
    (out / "study.json").write_text(json.dumps({"study": "paper-sensitivity", "points": 49}))
    assert cli.main(["sweep", str(write_study(GRID)), "--out", str(out), "--report"]) == 1
    assert capsys.readouterr().err.strip() == (
        f"dtcosim sweep: error: invalid command-line entry --out = '{out}': expected a folder of 'small' or a new one "
        "(it holds the results of 'paper-sensitivity'; their points would be mixed into one table); choose another "
        "--out")


def test_a_load_sets_results_in_the_earlier_default_folder_are_pointed_at(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    new = default_out_dir("paper-turbine")
    assert earlier_default_folder("paper-turbine", new) is None  # nothing there
    with Journal(Path("results/paper-turbine/journal.jsonl")) as j:
        j.append({"key": "k", "status": "ok", "study": "paper-turbine"})
    assert earlier_default_folder("paper-turbine", new) == Path("results/paper-turbine")
    assert earlier_default_folder("other-set", default_out_dir("other-set")) is None
    with Journal(new / "journal.jsonl") as j:  # moved (or started anew): nothing to point at
        j.append({"key": "k", "status": "ok", "study": "paper-turbine"})
    assert earlier_default_folder("paper-turbine", new) is None
