"""The Gearbox FMU and the host use one compiled kernel module per process (components.model.shared_module)."""

from __future__ import annotations

import sys

import pytest

from components.model.kernel import compiled_module


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
    # no build-specific copy (``_dtcosim_gearbox_<id>.components.model.compiled_kernel``) was imported
    assert _kernel_modules() == [host.__name__]
