"""One compiled module per kernel version, whichever copy of the sources asks (components.compile.jit)."""

from __future__ import annotations

import sys

import pytest

from components.compile.jit import load_compiled, try_compiled
from components.compile.sources import KernelSource

pytest.importorskip("numba")

KERNEL = "from .helper import scale\n\n\ndef scaled(x):\n    return scale(x)\n"


def _copy(root, package: str, factor: int, kernel: str = KERNEL) -> KernelSource:
    """A kernel package ``package`` under ``root``: ``kernel.py`` importing ``helper.py`` (scale by ``factor``)."""
    folder = root / package
    folder.mkdir(parents=True)
    (folder / "__init__.py").write_text("")
    (folder / "kernel.py").write_text(kernel)
    (folder / "helper.py").write_text(f"FACTOR = {factor}\n\n\ndef scale(x):\n    return FACTOR * x\n")
    return KernelSource("test", folder / "kernel.py")


@pytest.fixture
def packages(tmp_path, monkeypatch):
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path / "cache"))
    yield tmp_path
    for name in [name for name in sys.modules if name.startswith("_dtcosim_kernel_test_")]:  # the test's modules
        del sys.modules[name]


def test_copies_with_the_same_sources_share_one_compiled_module(packages):
    first = _copy(packages, "build_a", 3)
    second = _copy(packages, "build_b", 3)
    a = load_compiled(first)
    b = load_compiled(second)
    assert a is b and a.scaled(2) == 6
    assert a.__name__ == f"{second.shared_name}.kernel" and a.__name__.startswith("_dtcosim_kernel_test_")
    assert a.__file__ == str(first.entry)  # executed once, from the copy that asked first
    assert hasattr(a.scaled, "py_func") and hasattr(sys.modules[f"{first.shared_name}.helper"].scale, "py_func")


def test_a_different_dependency_is_another_module(packages):
    a = load_compiled(_copy(packages, "build_a", 3))
    c = load_compiled(_copy(packages, "build_c", 5))
    assert a is not c and (a.scaled(1), c.scaled(1)) == (3, 5)


def test_a_module_that_fails_to_execute_is_not_kept(packages):
    source = _copy(packages, "build_a", 3, kernel="from .helper import scale\nimport module_that_does_not_exist\n")
    with pytest.raises(ModuleNotFoundError, match="module_that_does_not_exist"):
        load_compiled(source)
    assert not [name for name in sys.modules if name.startswith(source.shared_name)]


def test_try_compiled_says_why_and_tries_once(packages):
    marker = packages / "attempts.txt"
    source = _copy(packages, "build_a", 3, kernel=f"open({str(marker)!r}, 'a').write('x')\nimport no_such_module\n")
    first = try_compiled(source)
    assert first == (None, "ModuleNotFoundError: No module named 'no_such_module'")
    assert try_compiled(source) == first and marker.read_text() == "x"
    module, reason = try_compiled(_copy(packages, "build_b", 3))
    assert reason is None and module.scaled(2) == 6


def test_compiled_forms_replace_the_numpy_forms(packages):
    """A module's ``COMPILED`` mapping swaps in the loop numba compiles; imported normally it runs its numpy form."""
    folder = packages / "build_d"
    folder.mkdir()
    (folder / "kernel.py").write_text(
        "import numpy as np\n\n\ndef total(x):\n    return float(np.sum(x)) + 0.5\n\n\n"
        "def _total_loop(x):\n    s = 0.0\n    for v in x:\n        s += v\n    return s\n\n\n"
        "COMPILED = {'total': _total_loop}\n")
    module = load_compiled(KernelSource("test", folder / "kernel.py"))
    import numpy as np

    assert module.total(np.array([1.0, 2.0])) == 3.0  # the loop, not the numpy form (+ 0.5)


BRIEF = """
import json, sys
import numpy as np
from components.model import kernel
from components.model.presets import preset
from components.model.assembly import Assembly
a = Assembly(preset("table6"))
a.static_deflection(25400.0)
a.law.evaluate(np.zeros((2, a.n_mesh)), np.zeros((2, a.n_mesh)))
brief = "numba" in sys.modules
a.law.evaluate(np.zeros((kernel.BRIEF_EVALUATIONS // a.n_mesh + 1, a.n_mesh)), np.zeros(1))
many = "numba" in sys.modules
a.static_deflection(25400.0)
print(json.dumps([brief, many, kernel.monolithic(brief=True)[1]]))
"""


@pytest.mark.parametrize("requested, expected", [
    ("auto", [False, True, "compiled"]),  # brief ones interpreted until numba's form is loaded, then compiled
    ("numpy", [False, False, "numpy"]),
    ("compiled", [True, True, "compiled"]),  # asked for: compiled even when brief
])
def test_brief_evaluations_do_not_load_numba_unless_it_is_loaded_or_asked_for(tmp_path, requested, expected):
    import json
    import os
    import subprocess

    env = {**os.environ, "DTCOSIM_KERNEL": requested}
    proc = subprocess.run([sys.executable, "-c", BRIEF], capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout) == expected
