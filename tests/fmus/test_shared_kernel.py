"""The Gearbox FMU and the host use one compiled kernel module per process (components.model.shared_module)."""

from __future__ import annotations

import sys

import pytest

from components.model.kernel import aot_kernel, compiled_module


def _kernel_modules() -> list[str]:
    """The kernel modules in this process: shared ones, and build-specific or host copies imported by name."""
    return sorted(name for name in sys.modules
                  if name.endswith(".model.compiled_kernel") or name.startswith("_dtcosim_compiled_kernel_"))


def test_the_gearbox_fmu_runs_on_the_hosts_kernel_module(fmu_path):
    from fmpy import simulate_fmu

    host, reason = compiled_module()
    if host is None:
        pytest.skip(f"compiled kernel unavailable: {reason}")
    result = simulate_fmu(str(fmu_path("Gearbox")), stop_time=0.01, step_size=1e-3, output=["shaft_torque"])
    assert len(result) == 11
    # no build-specific copy (``_dtcosim_gearbox_<id>.components.model.compiled_kernel``) was imported: only the
    # shared module of these sources (just in time, and its ahead-of-time twin ``<shared>_aot`` where built)
    shared = aot_kernel().shared
    assert _kernel_modules() and all(name in (shared, f"{shared}_aot") for name in _kernel_modules()), _kernel_modules()
    assert compiled_module()[0] is host


@pytest.mark.parametrize("name, output", [("Gearbox", "shaft_torque"), ("WindSource", "omega")])
def test_the_same_fmu_runs_again_after_its_first_extraction_is_gone(fmu_path, name, output):
    """fmpy deletes an FMU's extracted folder after a run; the modules the first run imported stay cached."""
    from fmpy import simulate_fmu

    runs = [simulate_fmu(str(fmu_path(name)), stop_time=0.01, step_size=1e-3, output=[output]) for _ in range(2)]
    assert list(runs[0][output]) == list(runs[1][output])
