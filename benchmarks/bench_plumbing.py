"""Cost of the FMI plumbing per communication step, with three trivial pythonfmu FMUs.

Source -> Relay -> Sink, each with one input and one output (the Source has no
input), doStep doing nothing but a copy: what remains is the FMI round trip
through fmpy + pythonfmu and the master's own work. Compared:

1. fmpy's high-level API in a plain Gauss-Seidel loop (``setReal``/``doStep``/``getReal``
   with Python lists, 8 calls per step) - DESIGN.md's reference loop;
2. a hand-written loop calling the raw FMI functions with pre-built arrays (the floor), with the
   GIL held over each call (as the master calls PythonFMUs) and released (ctypes' default);
3. the dtcosim master (Gauss-Seidel/Jacobi, hold/linear), recording every step, with each
   executor of its stepping plan: the Python loop (``orchestrator.cosim.stepping.python_loop``:
   what a C FMU, a typed port or a profile runs) and, where numba imports, the compiled loop
   (``orchestrator.cosim.stepping.compiled_loop``, the default for these FMUs: no Python and no
   ctypes conversion per call, so it can go below the "floor" of item 2).

Run: ``python benchmarks/bench_plumbing.py [--steps N] [--repeat N]``. Prints microseconds per
communication step and the master's overhead above the floor.
"""

from __future__ import annotations

import one_blas_thread  # noqa: F401 - first: one BLAS thread (CPU time without spinning workers)

import argparse
import tempfile
import textwrap
import time
from ctypes import c_double, c_uint
from pathlib import Path

SLAVES = {
    "BenchSource": """
        class BenchSource(Fmi2Slave):
            def __init__(self, **kw):
                super().__init__(**kw)
                self.y = 0.0
                self.register_variable(Real("y", causality=Fmi2Causality.output))
            def do_step(self, t, h):
                self.y = t
                return True
    """,
    "BenchRelay": """
        class BenchRelay(Fmi2Slave):
            def __init__(self, **kw):
                super().__init__(**kw)
                self.u = 0.0
                self.y = 0.0
                self.register_variable(Real("u", causality=Fmi2Causality.input))
                self.register_variable(Real("y", causality=Fmi2Causality.output))
            def do_step(self, t, h):
                self.y = self.u
                return True
    """,
    "BenchSink": """
        class BenchSink(Fmi2Slave):
            def __init__(self, **kw):
                super().__init__(**kw)
                self.u = 0.0
                self.y = 0.0
                self.register_variable(Real("u", causality=Fmi2Causality.input))
                self.register_variable(Real("y", causality=Fmi2Causality.output))
            def do_step(self, t, h):
                self.y = self.u
                return True
    """,
}

SCENARIO = """
name = "plumbing"
[simulation]
stop = {stop}
step = 1e-3
algorithm = "{algorithm}"
extrapolation = "{extrapolation}"
order = ["source", "relay", "sink"]  # the hand-written loop's order
[components.source]
fmu = "BenchSource.fmu"
[components.relay]
fmu = "BenchRelay.fmu"
[components.sink]
fmu = "BenchSink.fmu"
[[connections]]
from = "source.y"
to = "relay.u"
[[connections]]
from = "relay.y"
to = "sink.u"
[record]
variables = ["source.y", "relay.y", "sink.y"]
"""


def build(out: Path) -> dict[str, Path]:
    """Build the three trivial FMUs (outputs without direct feedthrough)."""
    import re
    import zipfile

    from pythonfmu.builder import FmuBuilder

    paths = {}
    for name, body in SLAVES.items():
        script = out / f"{name.lower()}_bench.py"
        script.write_text(
            "from pythonfmu import Fmi2Slave, Fmi2Causality, Real\n"
            # balance pythonfmu 0.7's extra release of the module namespace per instance (see fmus/build.py)
            "_namespace_refs = globals().setdefault('_namespace_refs', [])\n_namespace_refs.append(globals())\n"
            + textwrap.dedent(body))
        fmu = Path(FmuBuilder.build_FMU(script, dest=out))
        tmp = fmu.with_suffix(".tmp")
        with zipfile.ZipFile(fmu) as zin, zipfile.ZipFile(tmp, "w") as zout:
            for item in zin.infolist():
                data = zin.read(item.filename)
                if item.filename == "modelDescription.xml":
                    data = re.sub(rb'<Unknown index="(\d+)"\s*/>', rb'<Unknown index="\1" dependencies=""/>', data)
                zout.writestr(item, data)
        tmp.replace(fmu)
        paths[name] = fmu
    return paths


def _slaves(paths):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    out = []
    for name, path in paths.items():
        md = read_model_description(str(path), validate=False)
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(path)), modelIdentifier=name, instanceName=name.lower())
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        out.append(fmu)
    return out


def high_level_loop(paths, steps: int, h: float = 1e-3) -> float:
    """fmpy high-level API, Gauss-Seidel, 8 FMI calls per step; seconds per step."""
    src, relay, sink = _slaves(paths)
    t0 = time.perf_counter()
    for k in range(steps):
        t = k * h
        src.doStep(t, h)
        y = src.getReal([0])
        relay.setReal([0], y)
        relay.doStep(t, h)
        y = relay.getReal([1])
        sink.setReal([0], y)
        sink.doStep(t, h)
        sink.getReal([1])
    dt = (time.perf_counter() - t0) / steps
    for f in (src, relay, sink):
        f.terminate()
    return dt


def raw_loop(paths, steps: int, h: float = 1e-3, hold_gil: bool = True) -> float:
    """Hand-written loop, same 8 FMI calls per step, C functions called with plain addresses; s/step.

    The floor of the plumbing: nothing but the FMI round trips (no recording). ``hold_gil``:
    the prototypes the master uses for PythonFMUs (the GIL stays held over the call); False:
    the GIL-releasing prototypes (what the master used before, and uses for FMUs of other tools).
    """
    from ctypes import addressof, c_void_p, cast

    from orchestrator.cosim import fmi_runtime

    DO_STEP, REAL_VALUES = ((fmi_runtime.DO_STEP_HOLDING_GIL, fmi_runtime.REAL_VALUES_HOLDING_GIL) if hold_gil
                            else (fmi_runtime.DO_STEP, fmi_runtime.REAL_VALUES))
    fmus = _slaves(paths)
    c0, c1, c2 = (f.component for f in fmus)
    do0, do1, do2 = (DO_STEP(cast(f.dll.fmi2DoStep, c_void_p).value) for f in fmus)
    g0, g1, g2 = (REAL_VALUES(cast(f.dll.fmi2GetReal, c_void_p).value) for f in fmus)
    s1, s2 = (REAL_VALUES(cast(f.dll.fmi2SetReal, c_void_p).value) for f in fmus[1:])
    keep = [(c_uint * 1)(v) for v in (0, 0, 1)] + [(c_double * 1)() for _ in range(3)]  # keep alive
    vr_src, vr_in, vr_out, b0, b1, b2 = (addressof(a) for a in keep)
    t0 = time.perf_counter()
    for k in range(steps):
        t = k * h
        do0(c0, t, h, 1)
        g0(c0, vr_src, 1, b0)
        s1(c1, vr_in, 1, b0)
        do1(c1, t, h, 1)
        g1(c1, vr_out, 1, b1)
        s2(c2, vr_in, 1, b1)
        do2(c2, t, h, 1)
        g2(c2, vr_out, 1, b2)
    dt = (time.perf_counter() - t0) / steps
    for f in fmus:
        f.terminate()
    return dt


def master_loop(folder: Path, steps: int, algorithm: str, extrapolation: str, step_loop: str = "python") -> float:
    """The dtcosim master on the same FMUs (records every step); seconds per step of the loop."""
    from orchestrator.cosim.master import CoSimulation
    from orchestrator.cosim.system import resolve_system
    from orchestrator.inputs.scenario_file import load_scenario

    path = folder / f"plumbing-{algorithm}-{extrapolation}.toml"
    path.write_text(SCENARIO.format(stop=steps * 1e-3, algorithm=algorithm, extrapolation=extrapolation))
    out = CoSimulation(resolve_system(load_scenario(path)), step_loop=step_loop).run(handle_sigint=False)
    if algorithm == "gauss-seidel" and extrapolation == "hold":
        assert out.complete and abs(out.column("sink.y")[-1] - (steps - 1) * 1e-3) < 1e-12, "wrong data flow"
    return out.loop_time_s / out.steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=20000, help="communication steps per loop (default 20000)")
    parser.add_argument("--repeat", type=int, default=3, help="interleaved repetitions; the median is shown (default 3)")
    args = parser.parse_args()
    import statistics

    labels = ["fmpy high-level loop (8 calls/step)", "raw FMI calls, plain addresses (floor)",
              "  same, releasing the GIL per call"]
    variants = [(alg, ex) for alg in ("gauss-seidel", "jacobi") for ex in ("hold", "linear")]
    python = [f"dtcosim master, Python loop {alg}/{ex}" for alg, ex in variants]
    labels += python
    try:
        import numba  # noqa: F401 - optional: the compiled step loop
    except ImportError:
        compiled = []
    else:
        compiled = [f"  same, compiled loop {alg}/{ex}" for alg, ex in variants]
    labels += compiled
    times: dict[str, list[float]] = {label: [] for label in labels}
    with tempfile.TemporaryDirectory(prefix="dtcosim-bench-") as tmp:
        folder = Path(tmp)
        paths = build(folder)
        for _ in range(args.repeat):  # interleaved, so machine noise hits every variant alike
            times[labels[0]].append(high_level_loop(paths, args.steps))
            times[labels[1]].append(raw_loop(paths, args.steps))
            times[labels[2]].append(raw_loop(paths, args.steps, hold_gil=False))
            for label, (alg, ex) in zip(python, variants):
                times[label].append(master_loop(folder, args.steps, alg, ex, "python"))
            for label, (alg, ex) in zip(compiled, variants):
                times[label].append(master_loop(folder, args.steps, alg, ex, "compiled"))
    median = {label: statistics.median(v) for label, v in times.items()}
    floor = median[labels[1]]
    print(f"three trivial pythonfmu FMUs, {args.steps} steps, median of {args.repeat} interleaved runs")
    for label in labels:
        dt = median[label]
        print(f"  {label:<48} {dt * 1e6:7.1f} us/step   ({(dt - floor) * 1e6:+6.1f} us vs floor)")
    for i, (alg, ex) in enumerate(variants):
        line = f"master overhead {alg}/{ex}: Python loop {(median[python[i]] - floor) * 1e6:.1f} us"
        if compiled:
            line += f", compiled loop {(median[compiled[i]] - floor) * 1e6:.1f} us"
        print(line + " per step")


if __name__ == "__main__":
    main()
