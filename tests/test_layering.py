"""The architecture as a test: imports go one way, no import circle, and the FMU model imports no integrator or plotting code.

Every import statement counts, function-local ones too (:mod:`fmus.source_closure` reads them
from the syntax tree). The layers, bottom up::

    components.compile <- components.model <- components.reference <- components.analysis   the physics
    fmus.slaves <- fmus (build, registry, documentation, checks)            the FMUs
    orchestrator.inputs <- cosim <- interop <- run <- study <- commands     reading and running FMUs
                           cosim <- provision <- study, commands            finding and building them
    orchestrator.raster <- run                                              the run figures' renderer

The co-simulation only reads FMUs: below ``orchestrator.provision`` the orchestrator reaches
only the FMU's record, the registry and the archive checks of ``fmus`` (:data:`FMUS_READ`).
"""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import pytest

from fmus.source_closure import direct_imports, import_closure

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = {"components": ROOT / "components", "fmus": ROOT / "fmus", "orchestrator": ROOT / "orchestrator"}

_ORCHESTRATOR_READS = {"orchestrator.inputs", "orchestrator.cosim", "orchestrator.interop", "orchestrator.run",
                       "orchestrator.raster"}

#: layer -> the layers of its own top-level package it may import; everything imports the base modules
#: (``orchestrator.errors``, ...). ``fmus`` is the package's own modules (build, registry, documentation).
ALLOWED = {
    "components.compile": {"components.compile"},
    "components.model": {"components.compile", "components.model"},
    "components.reference": {"components.compile", "components.model", "components.reference"},
    "components.analysis": {"components.compile", "components.model", "components.reference", "components.analysis"},
    "fmus.slaves": {"fmus.slaves"},
    "fmus": {"fmus.slaves", "fmus"},
    "orchestrator.inputs": {"orchestrator.inputs"},
    "orchestrator.cosim": {"orchestrator.inputs", "orchestrator.cosim"},
    "orchestrator.provision": {"orchestrator.inputs", "orchestrator.cosim", "orchestrator.provision"},
    "orchestrator.interop": {"orchestrator.inputs", "orchestrator.cosim", "orchestrator.interop"},
    "orchestrator.raster": {"orchestrator.raster"},
    "orchestrator.run": {"orchestrator.inputs", "orchestrator.cosim", "orchestrator.interop", "orchestrator.run",
                         "orchestrator.raster"},
    "orchestrator.reports": {"orchestrator.reports"},
    "orchestrator.study": _ORCHESTRATOR_READS | {"orchestrator.provision", "orchestrator.study"},
    "orchestrator.commands": _ORCHESTRATOR_READS | {"orchestrator.provision", "orchestrator.study",
                                                    "orchestrator.reports", "orchestrator.commands"},
}

#: what of ``fmus`` a layer that only reads FMUs may reach: the FMU's record, the registry (with the cross-check
#: case each FMU declares), the archive checks
FMUS_READ = {"fmus", "fmus.slaves", "fmus.registry", "fmus.slaves.record", "fmus.archive_checks",
             "fmus.cross_check_case"}
#: layer -> the ``fmus`` modules it may reach (layers not named here may reach all of ``fmus``)
FMUS_ALLOWED = {
    "orchestrator.inputs": FMUS_READ,
    "orchestrator.cosim": FMUS_READ,
    # an SSP export writes copies of FMUs with other start values (fmus.start_values)
    "orchestrator.interop": FMUS_READ | {"fmus.start_values", "fmus.model_description", "fmus.slaves.interface"},
    "orchestrator.run": FMUS_READ | {"fmus.start_values", "fmus.model_description", "fmus.slaves.interface"},
    "orchestrator.reports": set(),
    "orchestrator.raster": set(),
}

def _layer(name: str) -> str | None:
    """The layer of module ``name`` (None: a package itself, or a base module of ``components`` or ``orchestrator``)."""
    parts = name.split(".")
    if len(parts) >= 2 and f"{parts[0]}.{parts[1]}" in ALLOWED:
        return f"{parts[0]}.{parts[1]}"
    return parts[0] if len(parts) >= 2 and parts[0] in ALLOWED else None


def _modules_of(layer: str) -> list[str]:
    folder = ROOT.joinpath(*layer.split("."))  # its modules and those of its own layers
    return [".".join((layer, *p.relative_to(folder).with_suffix("").parts))
            for p in sorted(folder.rglob("*.py")) if p.stem != "__init__"]


def _all_modules(top: str) -> list[str]:
    """Every module of package ``top`` (packages by their own name)."""
    out = []
    for path in sorted(PACKAGES[top].rglob("*.py")):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        out.append(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    return out


def import_circles(top: str) -> list[set[str]]:
    """The import circles among the modules of package ``top``."""
    return circles_of({m: direct_imports(m, PACKAGES) for m in _all_modules(top)})


def circles_of(graph: dict[str, set[str]]) -> list[set[str]]:
    """The circles of an import graph (module -> the modules it imports): strongly connected sets of two or more."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    circles = []

    def visit(v: str) -> None:  # Tarjan's algorithm
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = set()
            while True:
                w = stack.pop()
                on_stack.discard(w)
                group.add(w)
                if w == v:
                    break
            if len(group) > 1:
                circles.append(group)

    for module in graph:
        if module not in index:
            visit(module)
    return circles


@pytest.mark.parametrize("layer", sorted(ALLOWED))
def test_imports_go_one_way(layer):
    top = layer.split(".")[0]
    for module in _modules_of(layer):
        closure = import_closure([module], PACKAGES)  # everything it may import, directly or not, lazily or not
        for dep in closure:
            target = _layer(dep)
            if dep.split(".")[0] == top and target is not None:
                assert target in ALLOWED[layer], f"{module} reaches {dep}"
        if top == "components":  # the physics never imports the orchestrator or the FMU build
            assert not any(d.startswith(("orchestrator", "fmus")) for d in closure), module
        if top == "fmus":  # the FMUs know the physics, never the orchestrator
            assert not any(d.startswith("orchestrator") for d in closure), module
        if layer == "fmus.slaves":  # what an FMU carries: its slaves and the physics model, no analysis
            assert ALLOWED["components.model"] >= {_layer(d) for d in closure if d.startswith("components")} - {None}, \
                module
        if layer in FMUS_ALLOWED:
            reached = {d for d in closure if d.split(".")[0] == "fmus"}
            assert reached <= FMUS_ALLOWED[layer], f"{module} reaches {sorted(reached - FMUS_ALLOWED[layer])}"


def test_the_cosimulation_reads_fmus_and_builds_none():
    closure = import_closure(_modules_of("orchestrator.cosim"), PACKAGES)
    assert "fmus.build" not in closure and "fmus.documentation" not in closure
    assert not any(d.startswith("orchestrator.provision") for d in closure)


def test_import_circles_are_found(tmp_path):
    """The circle finder on a made-up package: a -> b -> c (function-local) -> a is one circle, d -> a is none."""
    pkg = tmp_path / "made_up"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from . import b\n")
    (pkg / "b.py").write_text("def f():\n    from .c import g\n")
    (pkg / "c.py").write_text("import made_up.a\n")
    (pkg / "d.py").write_text("from .a import x\n")
    graph = {m: direct_imports(m, {"made_up": pkg}) for m in ("made_up.a", "made_up.b", "made_up.c", "made_up.d")}
    assert graph == {"made_up.a": {"made_up.b"}, "made_up.b": {"made_up.c"}, "made_up.c": {"made_up.a"},
                     "made_up.d": {"made_up.a"}}
    assert circles_of(graph) == [{"made_up.a", "made_up.b", "made_up.c"}]
    assert circles_of({**graph, "made_up.c": set()}) == []


@pytest.mark.parametrize("top", sorted(PACKAGES))
def test_no_import_circle(top):
    assert import_circles(top) == []


def test_the_fmu_model_imports_no_integrator_of_scipy_and_no_matplotlib():
    code = ("import importlib, pkgutil, sys, components.model as m\n"
            "for i in pkgutil.iter_modules(m.__path__): importlib.import_module('components.model.' + i.name)\n"
            "print(sorted(k for k in sys.modules if k.startswith(('scipy.integrate', 'matplotlib'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert out.stdout.strip() == "[]"


def test_the_run_figures_renderer_imports_no_matplotlib():
    """orchestrator.raster draws without matplotlib: no import of it, nor of the matplotlib helpers of the base."""
    closure = import_closure(_modules_of("orchestrator.raster"), PACKAGES)
    assert "orchestrator.plotting" not in closure
    for module in closure.values():
        tree = ast.parse(module.path.read_text(encoding="utf-8"))
        names = [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]
        names += [n.module or "" for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and not n.level]
        assert not [n for n in names if n.split(".")[0] == "matplotlib"], module.path
