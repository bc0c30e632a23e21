"""The FMUs in other hosts and environments: a plain fmpy loop (also without dtcosim installed),
libcosim through libcosimpy, and two differently built FMUs in one process."""

from __future__ import annotations

import math
import shutil
import subprocess
import sys

import numpy as np
import pytest

from components.compile.aot import ENVIRONMENT_VARIABLE as AOT_VARIABLE
from components.compile.aot import missing
from components.model.gearbox_model import GearboxModel
from components.model.generator import GeneratorRotor
from components.model.presets import cosim_preset
from components.model.wind import PhasorStepper, RotorSpeedProcess, WindParameters
from fmus.build import SourceTree, build_fmu
from orchestrator.cosim.compiled_kernels import aot_kernels
from tests.helpers.fmu_hosts import SYSTEM_ENV, Instance, c_host, c_host_args, load_driver, run_python

H = 1.0e-3


@pytest.fixture(scope="module")
def loop_10s(fmu_dir):
    """The plain fmpy loop over 10 s in this process."""
    return load_driver("fmu_loop").run(fmu_dir, 10.0, H)


def reference_loop(t_end: float) -> dict[str, np.ndarray]:
    """The same Gauss-Seidel loop with the components called directly (as the FMUs compute it)."""
    drivetrain = cosim_preset("table6")
    gearbox = GearboxModel(drivetrain)
    wind = PhasorStepper(RotorSpeedProcess(WindParameters()))  # as the WindSource FMU steps it
    w0, p0 = wind.speed_and_angle()
    torque0 = drivetrain.generator.counter_torque_nm  # the Gearbox FMU's counter_torque input: its default
    gearbox.initialize(0.0, w0, p0, gearbox.ratio * w0, gearbox.ratio * p0, torque0)  # initialisation-mode outputs
    w_out = gearbox.output_speed_rad_s
    ratio = w_out / w0
    gearbox.initialize(0.0, w0, p0, w_out, ratio * p0, torque0)
    generator = GeneratorRotor(drivetrain.generator, w_out, ratio * p0)
    speed, torque = [generator.speed_rad_s], [gearbox.shaft_torque_nm]
    for n in range(int(round(t_end / H))):
        t = n * H
        gearbox.step(t, H, *wind.speed_and_angle(), generator.speed_rad_s, generator.angle_rad)
        generator.step(t, H, gearbox.shaft_torque_nm)
        wind.advance(t, H)
        speed.append(generator.speed_rad_s)
        torque.append(gearbox.shaft_torque_nm)
    return {"GeneratorRotor.omega": np.array(speed), "Gearbox.shaft_torque": np.array(torque)}


@pytest.mark.slow
def test_fmpy_loop_reproduces_the_components_bit_for_bit(fmu_dir):
    loop = load_driver("fmu_loop").run(fmu_dir, 1.0, H)
    reference = reference_loop(1.0)
    for key, values in reference.items():
        np.testing.assert_array_equal(loop[key], values, err_msg=key)


@pytest.mark.slow
@pytest.mark.parametrize("ahead_of_time", [False, True], ids=["numpy-fallback", "ahead-of-time-kernels"])
def test_loop_runs_in_a_fresh_venv_without_dtcosim(fmu_dir, bare_python, tmp_path, monkeypatch, ahead_of_time):
    """Only numpy and scipy: the numpy fallback, or the kernels compiled ahead of time that the FMUs carry."""
    if ahead_of_time and missing(aot_kernels()):
        pytest.skip("the kernels could not be compiled ahead of time on this machine")
    assert run_python(bare_python, "-c", "import components").returncode != 0
    assert run_python(bare_python, "-c", "import fmus").returncode != 0
    assert run_python(bare_python, "-c", "import numba").returncode != 0
    out = tmp_path / "bare.npz"
    driver = load_driver("fmu_loop").__file__
    # the default kernel choice (auto), whatever this process was asked for; an empty user cache: the compiled
    # modules come from the FMUs themselves
    env = {"DTCOSIM_KERNEL": "auto", AOT_VARIABLE: "1" if ahead_of_time else "0",
           "DTCOSIM_CACHE_DIR": str(tmp_path / "empty-cache")}
    result = run_python(bare_python, driver, str(fmu_dir), "1.0", str(H), str(out), env=env)
    assert result.returncode == 0, result.stderr[-3000:]
    # without numba and compiled modules, the Gearbox says once, through the FMI logger, that it runs the numpy path
    said = (result.stdout + result.stderr).count("compiled gearbox kernel unavailable")
    assert said == (0 if ahead_of_time else 1), result.stdout[-2000:]
    bare = np.load(out)
    assert not bare["numba_loaded"]
    modules = list(bare["modules"])
    assert modules and all(m.startswith("_dtcosim_") for m in modules), modules  # only the FMUs' private copies
    assert any(m.endswith("_aot") for m in modules) == ahead_of_time, modules
    # compare like with like: the compiled kernels run the numba-lowered code of this process's just-in-time ones
    monkeypatch.setenv("DTCOSIM_KERNEL", "auto" if ahead_of_time else "numpy")
    monkeypatch.setenv(AOT_VARIABLE, "0")
    in_process = load_driver("fmu_loop").run(fmu_dir, 1.0, H)
    for key in ("GeneratorRotor.omega", "Gearbox.shaft_torque", "Gearbox.stage1.F_sp[1]", "WindSource.omega"):
        if ahead_of_time:
            np.testing.assert_array_equal(bare[key], in_process[key], err_msg=key)
        else:
            np.testing.assert_allclose(bare[key], in_process[key], rtol=1e-9, atol=1e-6, err_msg=key)


@pytest.mark.slow
def test_libcosim_agrees_with_the_fmpy_loop(fmu_dir, loop_10s, libpython, tmp_path, this_python):
    pytest.importorskip("libcosimpy")
    out = tmp_path / "libcosim.npz"
    driver = load_driver("libcosim_run").__file__
    speed0 = float(loop_10s["initial_generator_speed"])
    result = run_python(this_python, driver, str(fmu_dir), "10.0", str(H), repr(speed0), str(out),
                        env={"LD_PRELOAD": str(libpython)})
    assert result.returncode == 0, result.stderr[-3000:]
    cosim = np.load(out)
    assert cosim["time"][-1] == pytest.approx(10.0 - H)
    fmpy_speed = np.interp(cosim["time"], loop_10s["time"], loop_10s["GeneratorRotor.omega"])
    relative = np.abs(cosim["GeneratorRotor.omega"] - fmpy_speed) / np.abs(fmpy_speed)
    assert relative.max() < 1.0e-3  # Jacobi (libcosim) vs Gauss-Seidel (fmpy loop) exchange
    assert relative.max() > 0.0  # libcosim really ran its own master algorithm
    np.testing.assert_allclose(cosim["WindSource.omega"], np.interp(cosim["time"], loop_10s["time"],
                                                                    loop_10s["WindSource.omega"]), rtol=1e-12)


MARKER = 12345.0
PATCH = f'''

# --- test patch: this copy of the code reports a marker rotor torque ---
GearboxModel.output_vector = lambda self: __import__('numpy').full(len(self.output_names), {MARKER!r})
GearboxModel.output_list = lambda self: [{MARKER!r}] * len(self.output_names)
'''


@pytest.mark.slow
def test_two_differently_built_fmus_each_run_their_own_code(built_fmus, tmp_path):
    installed = SourceTree.installed()
    patched_root = tmp_path / "patched"
    shutil.copytree(installed.components_dir, patched_root / "components", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(installed.slaves_dir, patched_root / "fmus" / "slaves", ignore=shutil.ignore_patterns("__pycache__"))
    with open(patched_root / "components" / "model" / "gearbox_model.py", "a") as f:
        f.write(PATCH)
    patched = build_fmu("Gearbox", tmp_path / "out", source=SourceTree.at(patched_root))
    original = built_fmus["Gearbox"]
    assert patched.package != original.package and patched.slave_module != original.slave_module

    def run_one_step(path, name):
        inst = Instance(path, name)
        inst.initialize()
        inst.step(0.0, H)
        torque = inst.get("torque_rotor")[0]
        inst.free()
        return torque

    # both in this process, in both orders
    first_patched = run_one_step(patched.path, "p1")
    first_original = run_one_step(original.path, "o1")
    assert first_patched == MARKER
    assert first_original != MARKER
    assert run_one_step(patched.path, "p2") == MARKER
    assert run_one_step(original.path, "o2") == first_original
    # each FMU imported its own copy; this process's components are untouched
    assert sys.modules[f"{patched.package}.components.model.gearbox_model"].__file__ != \
        sys.modules[f"{original.package}.components.model.gearbox_model"].__file__
    assert not isinstance(GearboxModel.rotor_torque_nm, float)


GEARBOX_INPUTS = ("omega_rotor", "phi_rotor", "omega_gen", "phi_gen")
#: what c_host reads of each FMU, and the inputs it drives (the Gearbox only)
C_HOST_CASES = {"Gearbox": ("shaft_torque", GEARBOX_INPUTS), "GeneratorRotor": ("omega", ()),
                "WindSource": ("omega", ()), "Rotor": ("omega", ()), "TorqueController": ("generator_torque", ())}


@pytest.mark.slow
def test_c_host_runs_the_gearbox_with_an_empty_environment_as_fmpy_does(fmu_path, tmp_path):
    """A plain C host (dlopen + FMI calls, drivers/c_host.c) with no environment but the system's PATH: no
    LD_PRELOAD, no PYTHONPATH. The FMU's binary finds its Python; the result is fmpy's in this process."""
    args = c_host_args(c_host(tmp_path), fmu_path("Gearbox"), tmp_path / "Gearbox", 200, "shaft_torque",
                       GEARBOX_INPUTS)
    result = subprocess.run(args, capture_output=True, text=True, timeout=300, env=SYSTEM_ENV)
    assert result.returncode == 0, result.stderr[-3000:]
    torque_c = float(result.stdout.split()[-1])
    inst = Instance(fmu_path("Gearbox"), "same-as-c")
    omega_rotor = 1.6755160819145563
    omega_gen = 0.99 * 100.0 * omega_rotor
    inst.initialize(omega_rotor=omega_rotor, phi_rotor=0.0, omega_gen=omega_gen, phi_gen=0.0)
    for n in range(200):
        t = n * H
        inst.set(omega_rotor=omega_rotor, phi_rotor=omega_rotor * t, omega_gen=omega_gen, phi_gen=omega_gen * t)
        inst.step(t, H)
    # equal to the last bits but for OpenBLAS's kernel choice, which OPENBLAS_CORETYPE (unset here) changes
    assert torque_c == pytest.approx(inst.get("shaft_torque")[0], rel=1e-9)
    inst.free()


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(C_HOST_CASES))
def test_c_host_runs_two_instances_and_a_new_one_after_freeing(name, fmu_path, tmp_path):
    """Two instances of one FMU side by side, then a new one after both are freed, in one C process with an empty
    environment: all give the same output and the host exits 0 (NTNU-IHB/PythonFMU #222, #228, #238)."""
    output, inputs = C_HOST_CASES[name]
    args = c_host_args(c_host(tmp_path), fmu_path(name), tmp_path / name, 100, output, inputs)
    result = subprocess.run(args, capture_output=True, text=True, timeout=300,
                            env={**SYSTEM_ENV, "INSTANCES": "2", "AGAIN": "1"})
    assert result.returncode == 0, result.stderr[-3000:]
    assert result.stdout.startswith("output ") and math.isfinite(float(result.stdout.split()[-1]))


@pytest.mark.slow
def test_an_fmu_whose_python_is_gone_says_where_it_looked(fmu_path, tmp_path):
    """The FMU moved to a machine without its Python: fmi2Instantiate returns NULL with a message naming what was
    tried and the variables that point elsewhere; the host exits on its own terms (no crash)."""
    host = c_host(tmp_path)
    folder = tmp_path / "WindSource"
    args = c_host_args(host, fmu_path("WindSource"), folder, 10, "omega")
    (folder / "resources" / "python.txt").write_text(
        "libpython=/nonexistent/lib/libpython3.99.so\nhome=/nonexistent\nversion=3.99\npath=/nonexistent/site\n")
    result = subprocess.run(args, capture_output=True, text=True, timeout=120, env=SYSTEM_ENV)
    assert result.returncode == 3 and "fmi2Instantiate failed" in result.stderr, result.stderr
    for part in ("cannot start Python: no Python 3.99 found for this FMU", "/nonexistent/lib/libpython3.99.so",
                 "libpython3.99.so.1.0", "DTCOSIM_FMU_LIBPYTHON", "DTCOSIM_FMU_PYTHONHOME", "DTCOSIM_FMU_PYTHONPATH"):
        assert part in result.stderr, part
