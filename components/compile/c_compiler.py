"""The machine's C compiler, which the kernels' ahead-of-time build (numba.pycc) and the FMU binary both need."""

from __future__ import annotations

import os
import shutil
import sysconfig

#: what to install where there is none (the message of every build that needs one)
INSTALL_HINT = "install one (Debian: apt install gcc)"


def c_compiler() -> str | None:
    """A C compiler's path: ``$CC``, then Python's own (sysconfig ``CC``), then cc, gcc, clang; None without one."""
    for candidate in (os.environ.get("CC"), (sysconfig.get_config_var("CC") or "").split(" ")[0], "cc", "gcc",
                      "clang"):
        if candidate and shutil.which(candidate):
            return shutil.which(candidate)
    return None
