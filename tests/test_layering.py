"""The architecture as a test: imports go one way, and the FMU model imports no integrator or plotting code."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from fmus.source_closure import import_closure

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = {"components": ROOT / "components", "orchestrator": ROOT / "orchestrator", "fmus": ROOT / "fmus"}

#: subpackage -> the subpackages (and base modules) it may import; everything imports the base modules
ALLOWED = {
    "components.model": {"components.model"},
    "components.reference": {"components.model", "components.reference"},
    "components.analysis": {"components.model", "components.reference", "components.analysis"},
    "orchestrator.inputs": {"orchestrator.inputs"},
    "orchestrator.cosim": {"orchestrator.inputs", "orchestrator.cosim"},
    "orchestrator.interop": {"orchestrator.inputs", "orchestrator.cosim", "orchestrator.interop"},
    "orchestrator.run": {"orchestrator.inputs", "orchestrator.cosim", "orchestrator.interop", "orchestrator.run"},
    "orchestrator.reports": {"orchestrator.reports"},
    "orchestrator.study": {"orchestrator.inputs", "orchestrator.cosim", "orchestrator.interop", "orchestrator.run",
                           "orchestrator.study"},
}


def _subpackage(name: str) -> str | None:
    parts = name.split(".")
    return ".".join(parts[:2]) if len(parts) >= 2 and f"{parts[0]}.{parts[1]}" in ALLOWED else None


def _modules_of(subpackage: str) -> list[str]:
    folder = ROOT.joinpath(*subpackage.split("."))  # its modules and those of its own subpackages
    return [".".join((subpackage, *p.relative_to(folder).with_suffix("").parts))
            for p in sorted(folder.rglob("*.py")) if p.stem != "__init__"]


@pytest.mark.parametrize("subpackage", sorted(ALLOWED))
def test_imports_go_one_way(subpackage):
    top = subpackage.split(".")[0]
    for module in _modules_of(subpackage):
        closure = import_closure([module], PACKAGES)  # everything it may import, directly or not, lazily or not
        for dep in closure:
            target = _subpackage(dep)
            if dep.split(".")[0] == top and target is not None:
                assert target in ALLOWED[subpackage], f"{module} reaches {dep}"
        if top == "components":  # the physics never imports the orchestrator or the FMU build
            assert not any(d.startswith(("orchestrator", "fmus")) for d in closure), module


def test_the_fmu_model_imports_no_integrator_of_scipy_and_no_matplotlib():
    code = ("import importlib, pkgutil, sys, components.model as m\n"
            "for i in pkgutil.iter_modules(m.__path__): importlib.import_module('components.model.' + i.name)\n"
            "print(sorted(k for k in sys.modules if k.startswith(('scipy.integrate', 'matplotlib'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert out.stdout.strip() == "[]"
