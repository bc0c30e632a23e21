"""The Gearbox FMU and the host use one compiled kernel per process (components.compile.jit, components.compile.aot)."""

from __future__ import annotations

import sys

import pytest

from components.model import kernel


def _compiled_kernel_modules() -> list[str]:
    """The compiled gearbox kernel's modules in this process (numba's and the ahead-of-time one)."""
    return sorted(name for name in sys.modules if name.startswith("_dtcosim_kernel_gearbox_"))


def test_the_gearbox_fmu_runs_on_the_hosts_compiled_kernel(fmu_path):
    from fmpy import simulate_fmu

    host, form, reason = kernel.gearbox()
    if form != "compiled":
        pytest.skip(f"compiled kernel unavailable: {reason}")
    result = simulate_fmu(str(fmu_path("Gearbox")), stop_time=0.01, step_size=1e-3, output=["shaft_torque"])
    assert len(result) == 11
    # the FMU's copy of the kernel sources compiled nothing of its own: the only compiled modules are those of
    # these sources (just in time, and the ahead-of-time twin ``<shared>_aot`` where built)
    shared = kernel.GEARBOX.shared_name
    names = _compiled_kernel_modules()
    assert names and all(name == shared or name.startswith(shared + ".") or name == f"{shared}_aot"
                         for name in names), names
    assert kernel.gearbox()[0] is host


@pytest.mark.parametrize("name, output", [("Gearbox", "shaft_torque"), ("WindSource", "omega")])
def test_the_same_fmu_runs_again_after_its_first_extraction_is_gone(fmu_path, name, output):
    """fmpy deletes an FMU's extracted folder after a run; the modules the first run imported stay cached."""
    from fmpy import simulate_fmu

    runs = [simulate_fmu(str(fmu_path(name)), stop_time=0.01, step_size=1e-3, output=[output]) for _ in range(2)]
    assert list(runs[0][output]) == list(runs[1][output])
