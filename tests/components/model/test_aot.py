"""The kernels compiled ahead of time (components.compile.aot): same results as numba's just-in-time kernels, no numba.

The extension modules are built once per machine by ``ensure_compiled_kernels`` (the
session fixture ``built_fmus`` and ``dtcosim build``/``run`` call it); the tests that use
them are skipped where they could not be built (no C compiler).
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from components.compile import aot
from components.compile.aot import AotKernel, facade, load_module
from components.compile.jit import load_compiled, try_compiled
from components.compile.sources import KernelSource
from components.model import kernel
from components.model.gearbox_model import GearboxModel
from components.model.generator import GeneratorRotor
from components.model.presets import cosim_preset
from components.model.wind import PhasorStepper, RotorSpeedProcess, WindParameters
from orchestrator.cosim.compiled_kernels import ensure_compiled_kernels

GEARBOX_AOT, WIND_AOT = AotKernel.of(kernel.GEARBOX), AotKernel.of(kernel.WIND)


@pytest.fixture(scope="module")
def built():
    """The ahead-of-time modules of this machine (built if missing), or skip."""
    problem = ensure_compiled_kernels()
    if problem is not None or aot.missing([GEARBOX_AOT, WIND_AOT]) or try_compiled(kernel.GEARBOX)[0] is None:
        pytest.skip(f"kernels not compiled ahead of time here ({problem})")
    return load_module(GEARBOX_AOT)


def _run(dt, module, steps=1500, h=5e-3):
    """Contact forces and outputs of a coupled run whose Gearbox steps through ``module``."""
    original = kernel.gearbox
    kernel.gearbox = lambda form=None: (module, "compiled", None)
    try:
        model = GearboxModel(dt, kernel="compiled")
    finally:
        kernel.gearbox = original
    wind = RotorSpeedProcess(WindParameters())
    w0, p0 = wind.speed(0.0), wind.angle(0.0)
    model.initialize(0.0, w0, p0, model.ratio * w0, model.ratio * p0)
    gen = GeneratorRotor(dt.generator, model.output_speed_rad_s, model.ratio * p0)
    out = []
    for k in range(steps):
        t = k * h
        model.step(t, h, wind.speed(t), wind.angle(t), gen.speed_rad_s, gen.angle_rad)
        gen.step(t, h, model.shaft_torque_nm)
        out.append(model.output_vector())
    return np.array(out), model.integrator


@pytest.mark.parametrize("make", [lambda: cosim_preset("table6"), lambda: cosim_preset("table5"),
                                  lambda: cosim_preset("table6").with_meshes(law="impact", stiffness_variation=0.3)],
                         ids=["table6", "table5-planetary", "table6-impact-tvms"])
def test_the_ahead_of_time_kernel_steps_bit_for_bit_as_the_just_in_time_one(built, make):
    dt = make()
    front = kernel.gearbox("compiled")[0]
    assert front.AHEAD_OF_TIME == built.__file__
    jit = load_compiled(kernel.GEARBOX)
    got, got_counters = _run(dt, front)
    expected, expected_counters = _run(dt, jit)
    np.testing.assert_array_equal(got, expected)
    assert got_counters == expected_counters
    assert np.ptp(got[:, 0]) > 1.0  # a real transient, not a constant


def test_the_wind_step_is_bit_for_bit_the_just_in_time_one(built):
    process = RotorSpeedProcess(WindParameters())
    stepper = PhasorStepper(process, kernel="compiled")  # whatever DTCOSIM_KERNEL says
    assert getattr(stepper._kernel, "AHEAD_OF_TIME", None), "the wind step is not the ahead-of-time module"
    jit = load_compiled(kernel.WIND).rotate_and_sum  # the just-in-time function
    z = np.exp(1j * np.linspace(0.0, 3.0, 256))
    rotation = np.exp(1j * 1e-3 * np.arange(1, 257))
    w, w_f = np.linspace(0.1, 1.0, 256), np.linspace(1.0, 0.1, 256)
    z_aot, z_jit = z.copy(), z.copy()
    assert stepper._kernel.rotate_and_sum(z_aot, rotation, w, w_f) == jit(z_jit, rotation, w, w_f)
    np.testing.assert_array_equal(z_aot, z_jit)


def test_the_facade_takes_other_names_from_the_just_in_time_module(built):
    front = kernel.gearbox("compiled")[0]
    assert front.OK == 0 and front.AOT_EXPORTS == kernel.gearbox("numpy")[0].AOT_EXPORTS  # constants of the source
    assert front.advance is load_compiled(kernel.GEARBOX).advance  # a function not exported: numba's
    with pytest.raises(AttributeError, match="no_such_function"):
        front.no_such_function  # noqa: B018


def test_the_facade_says_why_a_missing_name_has_no_just_in_time_module():
    module = type(sys)("stand_in_aot")
    module.__file__ = "/nowhere/stand_in_aot.so"
    front = facade(module, "stand_in_aot_facade", None, lambda: (None, "ImportError: No module named 'numba'"))
    with pytest.raises(AttributeError, match=r"monolithic_rhs .*unavailable \(ImportError: No module named 'numba'\)"):
        front.monolithic_rhs  # noqa: B018


def test_a_missing_damaged_or_disabled_module_is_not_loaded(tmp_path, monkeypatch):
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path))
    kernel = AotKernel("_dtcosim_test_kernel_0123456789abcdef", "nowhere:nothing")
    assert load_module(kernel) is None  # no file
    kernel.file().parent.mkdir(parents=True)
    kernel.file().write_bytes(b"not an ELF file")
    assert load_module(kernel) is None  # not importable: the just-in-time kernel runs instead
    assert kernel.module_name not in sys.modules
    monkeypatch.setenv(aot.ENVIRONMENT_VARIABLE, "0")
    assert not aot.enabled()


def test_the_key_follows_the_kernel_sources(tmp_path):
    entry, helper, other = tmp_path / "thing.py", tmp_path / "helper.py", tmp_path / "other.py"
    entry.write_text("from .helper import x\n")
    helper.write_text("x = 1\n")
    other.write_text("y = 1\n")
    first = KernelSource("thing", entry).shared_name
    assert KernelSource("thing", entry).files == (helper, entry)
    other.write_text("y = 2\n")
    assert KernelSource("thing", entry).shared_name == first  # a module the kernel does not import
    helper.write_text("x = 2\n")
    assert KernelSource("thing", entry).shared_name != first  # a changed kernel never loads an old module


_CHILD = textwrap.dedent("""
    import json, sys
    import numpy as np
    from components.model.wind import PhasorStepper, RotorSpeedProcess, WindParameters
    stepper = PhasorStepper(RotorSpeedProcess(WindParameters()))
    values = []
    for k in range(2000):
        stepper.advance(k * 1e-3, 1e-3)
        values.append(stepper.speed_and_angle())
    print(json.dumps({"numba": "numba" in sys.modules, "kernel": stepper.kernel,
                      "aot": getattr(stepper._kernel, "AHEAD_OF_TIME", None), "values": values}))
""")


@pytest.mark.slow
def test_a_module_built_here_runs_without_numba_and_as_the_jit_kernel(tmp_path):
    """``build_module`` into an empty cache (what a new machine does), then a process that never imports numba."""
    wind = WIND_AOT
    env_cache = {"DTCOSIM_CACHE_DIR": str(tmp_path), "DTCOSIM_KERNEL": "auto"}
    build = subprocess.run([sys.executable, "-m", "components.compile.aot", f"{wind.shared}={wind.provider}"],
                           capture_output=True, text=True, timeout=600, env={**__import__("os").environ, **env_cache})
    if build.returncode != 0 and "CompileError" in build.stderr + build.stdout:
        pytest.skip("no C compiler for numba.pycc")
    assert build.returncode == 0, build.stderr[-2000:]
    results = {}
    for label, extra in (("aot", {}), ("jit", {aot.ENVIRONMENT_VARIABLE: "0"})):
        proc = subprocess.run([sys.executable, "-c", _CHILD], capture_output=True, text=True, timeout=300,
                              env={**__import__("os").environ, **env_cache, **extra})
        assert proc.returncode == 0, proc.stderr[-2000:]
        results[label] = json.loads(proc.stdout.strip().splitlines()[-1])
    assert results["aot"]["aot"] and str(tmp_path) in results["aot"]["aot"]
    assert results["aot"]["numba"] is False and results["jit"]["numba"] is True
    assert results["aot"]["kernel"] == results["jit"]["kernel"] == "compiled"
    assert results["aot"]["values"] == results["jit"]["values"]


def test_the_fmus_carry_the_modules_of_their_kernel_sources(built, fmu_path):
    import zipfile

    for fmu in ("Gearbox", "WindSource"):
        with zipfile.ZipFile(fmu_path(fmu)) as archive:
            carried = {Path(n).name for n in archive.namelist() if f"/kernel/{aot.BUNDLE_FOLDER}/" in n}
        assert carried == {GEARBOX_AOT.file().name, WIND_AOT.file().name}, fmu


def test_a_failing_build_says_why_in_one_line_and_is_not_retried_on_every_run(tmp_path, monkeypatch):
    import orchestrator.cosim.compiled_kernels as compiled_kernels

    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path))
    fake = AotKernel("_dtcosim_test_kernel_0123456789abcdef", "components.model.kernel:no_such_provider")
    monkeypatch.setattr(compiled_kernels, "aot_kernels", lambda: (fake,))
    said = []
    problem = compiled_kernels.ensure_compiled_kernels(said.append)
    assert problem is not None and "no_such_provider" in problem and "\n" not in problem
    assert aot.failed_before(fake) == problem
    # then compiled just in time into numba's cache instead, which fails too for this kernel: the runs compile it
    assert said[-2].startswith(f"kernels not compiled ahead of time ({problem}): numba compiles them just in time")
    assert said[-1].startswith("not compiled just in time either (") and "no_such_provider" in said[-1]
    assert said[-1].endswith("each process compiles them itself") and not aot.is_warm(fake)

    def no_build(kernels, just_in_time=False):
        raise AssertionError(f"rebuilt {kernels}" if not just_in_time else "compiled just in time again")

    monkeypatch.setattr(compiled_kernels, "build_in_subprocess", no_build)
    monkeypatch.setattr(aot, "warm_mark", lambda shared: tmp_path / "warm")  # as if numba's cache held it
    (tmp_path / "warm").write_text("")
    said.clear()
    assert compiled_kernels.ensure_compiled_kernels(said.append) == problem  # remembered, not rebuilt
    assert len(said) == 1 and problem in said[0] and "numba runs them compiled just in time" in said[0]
    assert "`dtcosim build` tries the ahead-of-time build again" in said[0]
    with pytest.raises(AssertionError, match="rebuilt"):
        compiled_kernels.ensure_compiled_kernels(said.append, retry=True)  # dtcosim build tries again


def test_without_a_c_compiler_the_build_says_so_in_one_line(tmp_path, monkeypatch):
    pytest.importorskip("numba")
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(aot, "c_compiler", lambda: None)
    fake = AotKernel("_dtcosim_test_kernel_0123456789abcdef", "components.model.kernel:no_such_provider")
    with pytest.raises(RuntimeError, match=r"^no C compiler \(cc, gcc or clang\) for numba's ahead-of-time build: "
                                           r"install one \(Debian: apt install gcc\)$"):
        aot.build_module(fake)


def test_a_reason_of_several_lines_is_remembered_as_its_first(tmp_path, monkeypatch):
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path))
    fake = AotKernel("_dtcosim_test_kernel_0123456789abcdef", "components.model.kernel:no_such_provider")
    aot._remember(fake, "RuntimeError: numba's compiler is missing. If using conda try:\n\n#> conda install gcc\n")
    assert aot.failed_before(fake) == "RuntimeError: numba's compiler is missing. If using conda try:"


def test_a_background_build_is_one_detached_builder_that_records_what_it_did(tmp_path, monkeypatch):
    """The builder of a kernel that cannot be built (a provider that does not exist) records why and removes its mark;
    a second request while it runs gets its pid instead of a second builder."""
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path))
    fake = AotKernel("_dtcosim_test_kernel_fedcba9876543210", "components.model.kernel:no_such_provider")
    import os

    first = aot.build_in_background([fake])
    second = aot.build_in_background([fake])  # before the first has its mark, or after it: one builds, one leaves
    assert first is not None and second is not None
    for pid in {first, second}:
        os.waitpid(pid, 0)
    assert not aot.build_lock_file().exists() and aot.background_builder() is None
    assert "no_such_provider" in (aot.failed_before(fake) or "")
    log = aot.build_log().read_text()
    assert log.count("not built") == 1 and "no_such_provider" in log and "done in" in log


def test_a_builder_started_after_a_command_holds_the_mark_at_once_and_compiles_once_the_command_ended(
        tmp_path, monkeypatch):
    """The first run's builder (``after`` = the run's pid) leaves the machine to the run while it lasts."""
    import os
    import time

    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path))
    fake = AotKernel("_dtcosim_test_kernel_0123456789abcdef", "components.model.kernel:no_such_provider")
    command = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(1.5)"])
    builder = aot.build_in_background([fake], after=command.pid)
    deadline = time.monotonic() + 10
    while aot.background_builder() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    assert aot.background_builder() == builder  # the mark is there while it waits: no second builder starts
    assert aot.failed_before(fake) is None  # nothing compiled (nor failed) while the command runs
    command.wait()
    os.waitpid(builder, 0)
    log = aot.build_log().read_text()
    waited = float(log.split("waited ")[1].split(" s")[0])
    assert 0.5 < waited < aot.WAIT_FOR_STARTER_S and f"for pid {command.pid} to end" in log
    assert "no_such_provider" in (aot.failed_before(fake) or "") and not aot.build_lock_file().exists()


def test_a_dead_builders_mark_is_cleared(tmp_path, monkeypatch):
    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path))
    lock = aot.build_lock_file()
    lock.parent.mkdir(parents=True)
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    lock.write_text(f"{dead.pid}\n")
    assert aot.background_builder() is None and not lock.exists()


def _one_missing_kernel(monkeypatch, cache):
    """``orchestrator.cosim.compiled_kernels`` with one kernel to build (a fake) and the cache at ``cache``; the JIT
    switch and its reason restored after the test."""
    import orchestrator.cosim.compiled_kernels as compiled_kernels
    from components.compile.jit import JIT_OFF_REASON_VARIABLE, JIT_VARIABLE

    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(cache))
    monkeypatch.setenv(JIT_VARIABLE, "1")
    monkeypatch.setenv(JIT_OFF_REASON_VARIABLE, "")
    fake = AotKernel("_dtcosim_test_kernel_0011223344556677", "components.model.kernel:no_such_provider")
    monkeypatch.setattr(compiled_kernels, "aot_kernels", lambda: (fake,))
    return compiled_kernels, fake


def _ensure_in_background(monkeypatch, compiled_kernels):
    """``ensure_compiled_kernels(background=True)`` with the detached builder replaced by one of pid 4242: the builds it
    was asked to start (kernels, after), what it said and what it returned."""
    started, said = [], []
    monkeypatch.setattr(compiled_kernels, "build_in_background",
                        lambda todo, after=None: started.append((todo, after)) or 4242)
    problem = compiled_kernels.ensure_compiled_kernels(said.append, background=True)
    return started, said, problem


def test_the_first_run_does_not_wait_for_the_compiler(tmp_path, monkeypatch):
    """ensure_compiled_kernels(background=True): the build starts detached, this process compiles nothing just in
    time (DTCOSIM_JIT=0: its kernels run interpreted) and the message says what happens, without a duration."""
    from components.compile.jit import JIT_VARIABLE

    compiled_kernels, fake = _one_missing_kernel(monkeypatch, tmp_path)
    import os

    started, said, problem = _ensure_in_background(monkeypatch, compiled_kernels)
    assert started == [([fake], os.getpid())] and problem == "being compiled in the background (pid 4242)"

    assert os.environ[JIT_VARIABLE] == "0"
    # what the kernels of this process and its FMUs say when they run interpreted: why, with the builder's pid
    assert try_compiled(KernelSource("nojit", kernel.WIND.entry.with_name("contact.py"))) == (
        None, "no module compiled ahead of time yet: being compiled in the background for later runs (pid 4242)")
    (line,) = said
    assert line.startswith("compiling 1 kernel(s) ahead of time in the background for later runs (pid 4242, log ")
    assert line.endswith("until they are built, runs step them interpreted, which takes longer")
    assert not any(c.isdigit() for c in line.split("log ")[0].replace("4242", "").replace("1 kernel", ""))


def test_without_a_c_compiler_the_builder_compiles_the_kernel_just_in_time_and_later_processes_load_it(
        tmp_path, monkeypatch):
    """The background builder on a machine without a C compiler: the module is not built (remembered), numba's cache
    gets the kernel's entry points instead, and a later process that steps the kernel compiles nothing."""
    pytest.importorskip("numba")
    import os

    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path / "cache"))
    no_compilers = tmp_path / "bin"
    no_compilers.mkdir()
    monkeypatch.setenv("PATH", str(no_compilers))  # the builder runs sys.executable by its full path
    wind = AotKernel.of(kernel.WIND)
    os.waitpid(aot.build_in_background([wind]), 0)
    log = aot.build_log().read_text()
    assert f"{wind.module_name}: not built (RuntimeError: no C compiler (cc, gcc or clang)" in log
    assert f"{wind.shared}: compiled just in time into numba's cache in " in log, log
    assert aot.failed_before(wind).startswith("RuntimeError: no C compiler") and aot.is_warm(wind)
    assert not wind.file().exists() and not aot.build_lock_file().exists()
    later = textwrap.dedent("""
        import numpy as np
        from components.model.wind import PhasorStepper, RotorSpeedProcess, WindParameters
        stepper = PhasorStepper(RotorSpeedProcess(WindParameters()), kernel="compiled")
        stepper.reset(0.0)
        for k in range(5):
            stepper.advance(k * 0.01, 0.01)
        stepper.acceleration_and_jerk()
        print("stepped", stepper._kernel.__name__)
    """)
    env = {**os.environ, "NUMBA_DEBUG_CACHE": "1", "PYTHONPATH": str(Path(__file__).parents[3])}
    out = subprocess.run([sys.executable, "-c", later], capture_output=True, text=True, env=env, check=True).stdout
    assert "stepped _dtcosim_kernel_wind_" in out and "data loaded" in out, out
    assert "data saved" not in out, out  # every function the step called came from the cache


def _failed_kernel(monkeypatch, cache):
    """:func:`_one_missing_kernel` whose ahead-of-time build failed before."""
    compiled_kernels, fake = _one_missing_kernel(monkeypatch, cache)
    aot._remember(fake, "RuntimeError: no C compiler (cc, gcc or clang) for numba's ahead-of-time build")
    return compiled_kernels, fake


def test_without_a_module_a_run_leaves_the_just_in_time_compile_to_the_background(tmp_path, monkeypatch):
    """A run where the ahead-of-time build failed before and numba's cache is cold: the detached builder compiles the
    kernels just in time, this process runs them interpreted (it does not wait ~35 s unannounced), and says so."""
    import os

    from components.compile.jit import JIT_VARIABLE

    compiled_kernels, fake = _failed_kernel(monkeypatch, tmp_path)
    started, said, problem = _ensure_in_background(monkeypatch, compiled_kernels)
    assert started == [([fake], os.getpid())] and problem == aot.failed_before(fake)
    assert os.environ[JIT_VARIABLE] == "0"
    assert try_compiled(KernelSource("nojit", kernel.WIND.entry.with_name("contact.py"))) == (
        None, "no module compiled ahead of time yet: being compiled just in time in the background for later runs "
              "(pid 4242)")
    (line,) = said
    assert line.startswith(f"kernels not compiled ahead of time on this machine ({problem}): numba compiles them just "
                           "in time in the background for later runs instead (pid 4242, log ")
    assert "until then, runs step them interpreted" in line


def test_without_a_module_a_study_waits_for_the_just_in_time_compile_once(tmp_path, monkeypatch):
    """Builds and studies (not in the background) compile them just in time now, in child processes, and say so."""
    import os

    from components.compile.jit import JIT_VARIABLE

    compiled_kernels, fake = _failed_kernel(monkeypatch, tmp_path)
    asked = []
    monkeypatch.setattr(compiled_kernels, "build_in_subprocess",
                        lambda todo, just_in_time=False: asked.append((todo, just_in_time)))
    said = []
    assert compiled_kernels.ensure_compiled_kernels(said.append) == aot.failed_before(fake)
    assert asked == [([fake], True)] and os.environ[JIT_VARIABLE] == "1"
    assert said[0].endswith("numba compiles them just in time into its cache instead (once per machine and "
                            "version) ...")
    assert said[1].startswith("compiled 1 kernel(s) just in time in ")


def test_a_study_takes_what_a_builder_compiled_just_in_time_while_it_waited(tmp_path, monkeypatch):
    compiled_kernels, fake = _failed_kernel(monkeypatch, tmp_path)
    answers = iter([False, True])  # cold when asked, warm once the builder in progress has ended
    monkeypatch.setattr(compiled_kernels, "is_warm", lambda kernel: next(answers))
    monkeypatch.setattr(compiled_kernels, "build_in_subprocess", lambda *a, **k: pytest.fail("compiled again"))
    said = []
    assert compiled_kernels.ensure_compiled_kernels(said.append) == aot.failed_before(fake)
    (line,) = said
    assert line.endswith("numba runs them compiled just in time (`dtcosim build` tries the ahead-of-time build again)")


@pytest.mark.parametrize("background", [True, False], ids=["run", "study or build"])
def test_with_an_unwritable_cache_nothing_is_compiled_and_the_message_says_why(tmp_path, monkeypatch, background):
    """Compiled just in time without a cache to keep them, the kernels would be compiled anew by every process (~35 s):
    they run interpreted, and the message names the cache and the reason."""
    import os

    from components.compile.jit import JIT_VARIABLE

    blocked = tmp_path / "a-file"
    blocked.write_text("where the cache would be")
    compiled_kernels, _ = _one_missing_kernel(monkeypatch, blocked)
    said = []
    problem = compiled_kernels.ensure_compiled_kernels(said.append, background=background)
    assert problem.startswith("the per-user cache cannot be written: ") and os.environ[JIT_VARIABLE] == "0"
    (line,) = said
    assert line.startswith(f"the per-user cache {blocked} cannot be written (") and "runs step them interpreted" in line
    assert "DTCOSIM_CACHE_DIR chooses a writable folder" in line
    reason = try_compiled(KernelSource("nojit", kernel.WIND.entry.with_name("contact.py")))[1]
    assert reason.startswith("no module compiled ahead of time yet: the per-user cache cannot be written: ")


def test_without_just_in_time_compilation_a_kernel_runs_from_its_module_or_interpreted(tmp_path, monkeypatch):
    from components.compile.jit import JIT_VARIABLE

    monkeypatch.setenv("DTCOSIM_CACHE_DIR", str(tmp_path))  # no ahead-of-time modules here
    monkeypatch.setenv(JIT_VARIABLE, "0")  # set by the user: no reason given
    monkeypatch.delenv("DTCOSIM_JIT_OFF_REASON", raising=False)
    source = KernelSource("wind", kernel.WIND.entry)
    module, reason = try_compiled(KernelSource("nojit", kernel.WIND.entry.with_name("contact.py")))
    assert module is None and f"{JIT_VARIABLE}=0" in reason
    form = kernel.wind()
    if aot.load_module(AotKernel.of(source)) is None and try_compiled(source)[0] is None:
        assert form[1] == "numpy" and f"{JIT_VARIABLE}=0" in form[2]
