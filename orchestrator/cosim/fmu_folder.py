"""Where the project's FMUs live when a scenario does not say (a light module: the CLI imports it at start-up)."""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path


def default_fmu_dir() -> Path:
    """Directory of the built FMUs.

    ``$DTCOSIM_FMU_DIR`` if set; else the project's ``fmus/`` folder (the
    ``fmus`` package's own folder, where ``build_fmus.py`` writes) when running
    from a source checkout (``build_fmus.py`` beside that folder); else
    ``$XDG_CACHE_HOME/dtcosim/fmus`` (default ``~/.cache/dtcosim/fmus``) for an
    installed package, whose folder may not be writable.
    """
    env = os.environ.get("DTCOSIM_FMU_DIR")
    if env:
        return Path(env)
    spec = importlib.util.find_spec("fmus")
    if spec is not None and spec.origin:
        package_dir = Path(spec.origin).resolve().parent
        if (package_dir.parent / "build_fmus.py").is_file():
            return package_dir
    cache = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(cache) / "dtcosim" / "fmus"
