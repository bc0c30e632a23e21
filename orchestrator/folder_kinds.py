"""What a result folder holds, so that the results of a run and of a study never mix in one folder.

A run's folder holds ``summary.json`` (with its ``scenario``); a study's or a load set's
folder holds ``journal.jsonl`` (each record with its ``study``). ``dtcosim run`` and
``dtcosim loads`` of one name (``openfast-dlc11`` is both a scenario and a load-case set)
write to different default folders (``results/<scenario>/``, ``results/loads/<set>/``,
``results/sweeps/<study>/``); a folder named with ``--out`` that already holds results of
another kind, or of another study, is refused before anything is written, naming what
it holds.
"""

from __future__ import annotations

import json
from pathlib import Path

#: the file that marks each kind of result folder
RUN_MARKER, STUDY_MARKER = "summary.json", "journal.jsonl"


def _first_json(path: Path, lines: bool = False) -> dict | None:
    try:
        with path.open(encoding="utf-8") as fh:
            text = fh.readline() if lines else fh.read(1 << 20)
        value = json.loads(text)
    except (OSError, ValueError, UnicodeDecodeError):
        return None
    return value if isinstance(value, dict) else None


def held_results(folder: str | Path) -> tuple[str, str | None] | None:
    """``("run", scenario)`` or ``("study", study name)`` of the results ``folder`` holds; None if none."""
    folder = Path(folder)
    journal = folder / STUDY_MARKER
    if journal.is_file():
        record = _first_json(journal, lines=True) or {}
        return "study", record.get("study") if isinstance(record.get("study"), str) else None
    summary = folder / RUN_MARKER
    if summary.is_file():
        data = _first_json(summary) or {}
        return "run", data.get("scenario") if isinstance(data.get("scenario"), str) else None
    return None


def mixing_problem(folder: str | Path, kind: str, name: str | None = None) -> str | None:
    """Why ``folder`` cannot take results of ``kind`` (``"run"``, ``"study"``) named ``name``; None if it can.

    A run may replace another run's results (it clears them: :mod:`orchestrator.run.run_folder`);
    a study resumes only its own journal.
    """
    held = held_results(folder)
    if held is None:
        return None
    held_kind, held_name = held
    what = {"run": "the results of a run", "study": "the journal of a study or load set"}[held_kind]
    named = f" {held_name!r}" if held_name else ""
    if held_kind != kind:
        marker = RUN_MARKER if held_kind == "run" else STUDY_MARKER
        return (f"a folder for {'a run' if kind == 'run' else 'a study or load set'}; this one holds {what}{named} "
                f"({marker}): choose another --out (the results of runs, sweeps and load sets never share a folder)")
    if kind == "study" and name is not None and held_name is not None and held_name != name:
        return (f"a folder for the study or load set {name!r}; this one holds {what}{named} ({STUDY_MARKER}): "
                "choose another --out (a study resumes only its own journal)")
    return None
