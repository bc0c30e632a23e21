"""Which command's results an output folder holds: a run's, or a sweep's or load set's; folders never mix.

``dtcosim run`` writes one run into its folder (``summary.json`` lists the files,
:mod:`orchestrator.run.run_folder`); ``dtcosim sweep`` and ``dtcosim loads`` write
a journal of points (``journal.jsonl``, :mod:`orchestrator.study.journal`) and the
table, plots and ``study.json`` made from it. The two kinds would replace or
outlive each other's files in one folder (a ``run`` and a ``loads`` of
``openfast-dlc11`` both wrote ``results/openfast-dlc11/``), so their default
folders differ (``results/<scenario>/``, ``results/<study>/``,
``results/loads/<set>/``) and a command refuses a folder that holds the other
kind's results (or another study's journal), naming the folder, what it holds and
what to do. This module holds the file names that mark each kind; the modules that
write them take their names from here.
"""

from __future__ import annotations

import json
from pathlib import Path

from .errors import EntryError

#: the summary every run writes and keeps up to date (``orchestrator.run.run_folder``)
RUN_SUMMARY = "summary.json"
#: the journal every sweep and load set appends to (``orchestrator.study.journal``)
STUDY_JOURNAL = "journal.jsonl"
#: the summary a sweep or load set writes from its journal (``orchestrator.study.report``)
STUDY_SUMMARY = "study.json"
#: the folder under ``results/`` that holds the load sets' folders by default
LOADS_FOLDER = "loads"


class MixedFolderError(EntryError):
    """The output folder holds another command's results (names the option, the folder and what it holds)."""

    kind = "command-line"


def _json(path: Path) -> object:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def run_in(folder: str | Path) -> str | None:
    """The scenario whose run's summary ``folder`` holds (None: no run's summary)."""
    summary = _json(Path(folder) / RUN_SUMMARY)
    if isinstance(summary, dict) and "scenario" in summary and "complete" in summary:
        return str(summary["scenario"])
    return None


def study_in(folder: str | Path) -> str | None:
    """The study or load set whose journal or summary ``folder`` holds ("" when it names none; None: neither)."""
    folder = Path(folder)
    summary = _json(folder / STUDY_SUMMARY)
    if isinstance(summary, dict) and "study" in summary:
        return str(summary["study"])
    journal = folder / STUDY_JOURNAL
    if not journal.is_file():
        return None
    try:
        with open(journal, encoding="utf-8", errors="replace") as fh:
            first = fh.readline(1 << 20)
        record = json.loads(first)
    except (OSError, ValueError):
        return ""
    return str(record.get("study", "")) if isinstance(record, dict) else ""


def check_for_run(folder: str | Path, key: str = "--out") -> None:
    """Refuse a folder that holds a sweep's or load set's results for a run.

    Raises
    ------
    MixedFolderError
    """
    study = study_in(folder)
    if study is not None:
        named = f" of {study!r}" if study else ""
        raise MixedFolderError(key, str(folder), f"a folder without a sweep's or load set's results (it holds the "
                               f"journal{named}, {STUDY_JOURNAL}: a run's files beside it would mix two commands' "
                               f"results); choose another {key}")


def check_for_study(folder: str | Path, study: str, key: str = "--out") -> None:
    """Refuse a folder that holds a run's results, or another study's journal, for the sweep or load set ``study``.

    Raises
    ------
    MixedFolderError
    """
    scenario = run_in(folder)
    if scenario is not None:
        raise MixedFolderError(key, str(folder), f"a folder without a run's results (it holds the {RUN_SUMMARY} of a "
                               f"run of {scenario!r}: the study's files beside it would mix two commands' results); "
                               f"choose another {key}")
    held = study_in(folder)
    if held and held != study:
        raise MixedFolderError(key, str(folder), f"a folder of {study!r} or a new one (it holds the results of "
                               f"{held!r}; their points would be mixed into one table); choose another {key}")
