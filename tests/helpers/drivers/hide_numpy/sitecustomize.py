"""PYTHONPATH shim: numpy cannot be imported by the dtcosim FMUs' code (modules named ``_dtcosim_*``).

The host (fmpy) imports numpy itself, so numpy cannot simply be uninstalled; this shim
makes every ``import numpy`` executed by an FMU's embedded code raise
``ModuleNotFoundError`` as if numpy were missing from the interpreter, and leaves
every other importer alone. Usage: ``PYTHONPATH=<this directory> python host.py``.
"""

import builtins

HIDDEN = "numpy"
_import = builtins.__import__


def _hiding_import(name, globals=None, locals=None, fromlist=(), level=0):
    importer = (globals or {}).get("__name__") or ""
    if level == 0 and name.split(".")[0] == HIDDEN and importer.startswith("_dtcosim_"):
        raise ModuleNotFoundError(f"No module named {HIDDEN!r}", name=HIDDEN)
    return _import(name, globals, locals, fromlist, level)


builtins.__import__ = _hiding_import
