"""The per-user cache folder of dtcosim: compiled kernels, numba's cache, built FMUs."""

from __future__ import annotations

import os
import sys
from pathlib import Path

#: environment variable naming the per-user cache folder
CACHE_VARIABLE = "DTCOSIM_CACHE_DIR"


def user_cache_root() -> Path:
    """Per-user cache directory of dtcosim (not created here)."""
    explicit = os.environ.get(CACHE_VARIABLE)
    if explicit:
        return Path(explicit)
    if sys.platform == "win32":
        base = Path(os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local")
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Caches"
    else:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "dtcosim"
