"""Where a command finds its FMUs: ``--fmu-dir`` and ``--no-build``, shared by every command that runs FMUs.

One definition of the search (the scenario's own folder, then ``--fmu-dir``, else
``$DTCOSIM_FMU_DIR`` or ``fmus/`` in the per-user cache: :func:`orchestrator.provision.folders.default_fmu_dir`)
and of building the project's FMUs that are missing or stale into that folder
(:func:`orchestrator.provision.project_fmus.ensure_fmus`).
"""

from __future__ import annotations

import argparse
from pathlib import Path


def add_fmu_arguments(p: argparse.ArgumentParser, whose: str = "the scenario's", build: bool = True) -> None:
    """Add ``--fmu-dir`` (and ``--no-build`` unless ``build`` is False) to a subcommand's parser.

    Parameters
    ----------
    p : argparse.ArgumentParser
    whose : str
        Whose FMUs the folder is searched for, in the help text ("the study's base scenario's").
    build : bool
        Whether the command builds missing project FMUs (then ``--no-build`` turns that off).
    """
    p.add_argument("--fmu-dir", type=Path, default=None,
                   help=f"directory searched for {whose} FMUs after the scenario's own folder (default: "
                        f"$DTCOSIM_FMU_DIR, else fmus/ in the per-user cache ~/.cache/dtcosim); missing project FMUs "
                        "are built into it")
    if build:
        p.add_argument("--no-build", action="store_true",
                       help="do not build missing or stale project FMUs (fail instead)")


def said_once(say):
    """``say`` for what preparing FMUs reports, each line once: a command that prepares them more than once (a load
    set resolves its base scenario, then its study) repeats no message."""
    seen: set[str] = set()

    def report(message: str) -> None:
        if message not in seen:
            seen.add(message)
            say(message)

    return report
