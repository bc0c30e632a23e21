"""The compiled kernel's disk cache: a fresh process loads the machine code without numba's compilation context.

numba's own cache load imports and installs every lowering registry and compiles its
runtime's LLVM module (~45 MB resident); :func:`components.compile.numba_cache.register_runtime_symbols`
registers only the runtime's C helpers. The fresh process must hit the cache, must not
have imported numba's lowerings, and its compiled steps must match the interpreted kernel.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest

from components.compile.aot import ENVIRONMENT_VARIABLE
from components.compile.jit import try_compiled
from components.model.kernel import GEARBOX, jit_gearbox

ck, _reason = try_compiled(GEARBOX)
pytestmark = pytest.mark.skipif(ck is None, reason=f"compiled kernel unavailable: {_reason}")

#: modules numba imports when it refreshes its compilation context (numba.core.cpu.load_additional_registries)
LOWERINGS = ("numba.np.arraymath", "numba.np.linalg", "numba.typed.dictimpl", "numba.cpython.listobj")

_CHILD = textwrap.dedent("""
    import json, sys
    import numpy as np
    from components.model.gearbox_model import GearboxModel
    from components.model.generator import GeneratorRotor
    from components.model.presets import cosim_preset
    from components.model.wind import RotorSpeedProcess, WindParameters
    from components.compile.jit import load_compiled
    from components.model.kernel import GEARBOX

    # one communication step of the compiled kernel from states of an interpreted run (start-up impacts included)
    dt = cosim_preset("table6")
    wind = RotorSpeedProcess(WindParameters())
    h = 2e-3
    reference, compiled = GearboxModel(dt, kernel="numpy"), GearboxModel(dt, kernel="compiled")
    w0, p0 = wind.speed(0.0), wind.angle(0.0)
    reference.initialize(0.0, w0, p0, reference.ratio * w0, reference.ratio * p0)
    gen = GeneratorRotor(dt.generator, reference.output_speed_rad_s, reference.ratio * p0)
    samples, outputs = [], []
    for k in range(100):
        t = k * h
        inputs = (wind.speed(t), wind.angle(t), gen.speed_rad_s, gen.angle_rad)
        state = json.dumps(reference.get_state()) if k % 10 == 0 else None
        reference.step(t, h, *inputs)
        outputs.append(reference.output_vector())
        if state is not None:
            samples.append((t, inputs, state, outputs[-1]))
        gen.step(t, h, reference.shaft_torque_nm)
    scale = np.abs(outputs).max(axis=0) + 1e-300
    difference = 0.0
    for t, inputs, state, expected in samples:
        compiled.set_state(json.loads(state))
        compiled.step(t, h, *inputs)
        difference = max(difference, float(np.max(np.abs(compiled.output_vector() - expected) / scale)))
    ck = load_compiled(GEARBOX)  # the module GearboxModel used (one per process for the same sources)
    print(json.dumps({
        "disk_cache": ck.DISK_CACHE,
        "hits": sum(ck.gearbox_step.stats.cache_hits.values()),
        "misses": sum(ck.gearbox_step.stats.cache_misses.values()),
        "lowerings": [m for m in __LOWERINGS__ if m in sys.modules],
        "difference": difference,
    }))
""").replace("__LOWERINGS__", repr(LOWERINGS))


def test_a_fresh_process_runs_the_cached_kernel_without_numba_lowerings():
    if not ck.DISK_CACHE:
        pytest.skip("numba's cache classes are not as expected: the kernel compiles in memory")
    jit_gearbox()  # writes the cache if this process compiled it
    # the just-in-time kernel's cache (not the module compiled ahead of time)
    proc = subprocess.run([sys.executable, "-c", _CHILD], capture_output=True, text=True, timeout=300,
                          env={**os.environ, ENVIRONMENT_VARIABLE: "0"})
    assert proc.returncode == 0, proc.stderr
    got = json.loads(proc.stdout.strip().splitlines()[-1])
    assert got["disk_cache"] and (got["hits"], got["misses"]) == (1, 0), got
    assert got["lowerings"] == [], got
    assert got["difference"] < 1e-12, got


_SYMBOLS = textwrap.dedent("""
    import json
    import llvmlite.binding as ll
    registered = []
    add_symbol = ll.add_symbol
    ll.add_symbol = lambda name, address: (registered.append(name), add_symbol(name, address))[1]
    from numba.core.registry import cpu_target
    from components.compile.numba_cache import register_runtime_symbols
    context = cpu_target.target_context
    start = len(registered)
    assert register_runtime_symbols()
    light = set(registered[start:])
    context.refresh()  # what numba's own cache load does first
    print(json.dumps({"light": sorted(light), "refresh": sorted(set(registered[start:]) - light)}))
""")


def test_the_light_load_registers_every_symbol_a_context_refresh_would():
    """A symbol the cached machine code needs and nobody registered would abort the process in LLVM."""
    proc = subprocess.run([sys.executable, "-c", _SYMBOLS], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    got = json.loads(proc.stdout.strip().splitlines()[-1])
    assert any(name.startswith("NRT_") for name in got["light"]), got
    assert got["refresh"] == [], got



def test_numba_s_warning_about_a_function_it_cannot_cache_finds_the_file_it_names(tmp_path, monkeypatch):
    """numba warns where it cannot cache a function (lifted loops, dynamic globals: met at ``NUMBA_OPT=0``) and names
    the locator's file; the stable cache's locator has it, so the compile goes on in memory (it raised
    AttributeError)."""
    from types import SimpleNamespace

    from numba import njit
    from numba.core.errors import NumbaWarning

    from components.compile.numba_cache import enable_stable_cache

    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path))

    def twice(x):
        return 2 * x

    dispatcher = njit(cache=False)(twice)
    assert enable_stable_cache([dispatcher], __file__, "test_uncachable")
    lifted = SimpleNamespace(lifted=[SimpleNamespace(can_cache=False)], fndesc=SimpleNamespace(qualname="twice"))
    with pytest.warns(NumbaWarning, match='Cannot cache compiled function "twice" as it uses lifted code'):
        assert dispatcher._cache._impl.check_cachable(lifted) is False
    assert dispatcher(2.0) == 4.0
