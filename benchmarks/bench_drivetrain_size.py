#!/usr/bin/env python3
"""Cost per communication step of the Gearbox FMU against the number of planets and of stages.

Variants of the Table 6 gearbox, each built into its own Gearbox FMU in this run:

* planets: stage 1 with 3 (Table 6 itself), 4, 5 and 7 planets (torsional structure only:
  Table 6's large planets would not fit beyond 3; the cost does not depend on that);
* stages: the first 1, 2 or 3 stages of Table 6, and 4 or 5 stages (Table 6 plus one or two
  more parallel stages like its stage 3, joined by shafts like its shaft 2).

The generator torque of every variant is set so that the rotor torque is Table 6's
(25.4 kN m x 100), so every variant runs at the same rotor load. Each FMU is driven through fmpy
(``setReal(4) + doStep + getReal(1)`` at H = 1 ms, low-level ``FMU2Slave`` calls) with
the rotor and generator motion of its own coupled components run (computed beforehand),
after a start-up that is not timed. One figure is the median over ``--repeat`` blocks of
``--steps`` steps of the CPU time (``time.process_time``) per step; the variants take
turns block by block, so load changes on the shared machine hit them alike. Printed as
ratios to the Table 6 gearbox of the same run, next to the ratio of degrees of freedom.

Usage::

    python benchmarks/bench_drivetrain_size.py [--steps 500] [--repeat 5] [--warmup 3.0]
"""

from __future__ import annotations

import one_blas_thread  # noqa: F401 - first: one BLAS thread (CPU time without spinning workers)

import argparse
import statistics
import sys
import tempfile
import time
from ctypes import c_double, c_uint32
from dataclasses import replace
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from components.model.assembly import Assembly
from components.model.drivetrain import Drivetrain
from components.model.gearbox_model import GearboxModel
from components.model.generator import GeneratorRotor
from components.model.presets import cosim_preset
from components.model.stages import ParallelStage
from components.model.wind import RotorSpeedProcess, WindParameters
from fmus.build import build_fmu

STEP_S = 1.0e-3
INPUTS = ("omega_rotor", "phi_rotor", "omega_gen", "phi_gen")
ROTOR_TORQUE_NM = 25400.0 * 100.0


def _at_table6_load(dt: Drivetrain) -> Drivetrain:
    return replace(dt, generator=replace(dt.generator, counter_torque_nm=ROTOR_TORQUE_NM / dt.ratio))


def variants() -> dict[str, Drivetrain]:
    """Name -> co-simulation drivetrain; ``table6`` first (the baseline)."""
    t6 = cosim_preset("table6")
    s1, s2, s3 = t6.stages
    sh1, sh2 = t6.shafts
    out = {"table6": t6}
    for n in (4, 5, 7):
        out[f"stage1 {n} planets"] = _at_table6_load(replace(t6, stages=(replace(s1, n_planets=n), s2, s3)))
    out["1 stage"] = _at_table6_load(replace(t6, stages=(s1,), shafts=()))
    out["2 stages"] = _at_table6_load(replace(t6, stages=(s1, s2), shafts=(sh1,)))
    extra = [replace(s3, name=f"stage{k}") for k in (4, 5)]
    assert all(isinstance(s, ParallelStage) for s in extra)
    for k in (4, 5):
        stages = (s1, s2, s3, *extra[: k - 3])
        shafts = (sh1, sh2, *[replace(sh2, name=f"shaft{j}") for j in range(3, k)])
        out[f"{k} stages"] = _at_table6_load(
            replace(t6, stages=stages, shafts=shafts, output_shaft=replace(t6.output_shaft, name=f"shaft{k}")))
    return out


def reference_inputs(drivetrain: Drivetrain, n_steps: int) -> tuple[np.ndarray, tuple]:
    """Gearbox inputs of a coupled components run (wind -> gearbox -> generator), shape (n_steps, 4)."""
    gearbox = GearboxModel(drivetrain)
    wind = RotorSpeedProcess(WindParameters())
    w0, p0 = wind.speed(0.0), wind.angle(0.0)
    gearbox.initialize(0.0, w0, p0, gearbox.ratio * w0, gearbox.ratio * p0)
    w_out = gearbox.output_speed_rad_s
    ratio = w_out / w0
    gearbox.initialize(0.0, w0, p0, w_out, ratio * p0)
    generator = GeneratorRotor(drivetrain.generator, w_out, ratio * p0)
    inputs = np.empty((n_steps, 4))
    t_wind = 0.0
    for n in range(n_steps):
        t = n * STEP_S
        inputs[n] = wind.speed(t_wind), wind.angle(t_wind), generator.speed_rad_s, generator.angle_rad
        gearbox.step(t, STEP_S, *inputs[n])
        generator.step(t, STEP_S, gearbox.shaft_torque_nm)
        t_wind = t + STEP_S
    return inputs, (w0, p0, w_out, ratio * p0)


class Stepper:
    """An instantiated Gearbox FMU stepped with pre-built arrays; CPU time per block."""

    def __init__(self, path: Path, initial: tuple, name: str) -> None:
        md = read_model_description(str(path))
        vr = {v.name: v.valueReference for v in md.modelVariables}
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(path)),
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        self.fmu.setReal([vr[k] for k in INPUTS], list(initial))
        self.fmu.exitInitializationMode()
        self.in_vr = (c_uint32 * 4)(*[vr[n] for n in INPUTS])
        self.in_val = (c_double * 4)()
        self.out_vr = (c_uint32 * 1)(vr["shaft_torque"])
        self.out_val = (c_double * 1)()

    def run(self, rows: list, first_step: int) -> float:
        """Step through ``rows``; returns the CPU time [s]."""
        fmu, component = self.fmu, self.fmu.component
        set_real, do_step, get_real = fmu.fmi2SetReal, fmu.fmi2DoStep, fmu.fmi2GetReal
        in_vr, in_val, out_vr, out_val = self.in_vr, self.in_val, self.out_vr, self.out_val
        start = time.process_time()
        for k, row in enumerate(rows):
            in_val[:] = row
            set_real(component, in_vr, 4, in_val)
            if do_step(component, (first_step + k) * STEP_S, STEP_S, 1) != 0:
                raise RuntimeError(f"fmi2DoStep failed at step {first_step + k}")
            get_real(component, out_vr, 1, out_val)
        return time.process_time() - start

    def close(self) -> None:
        self.fmu.terminate()
        self.fmu.freeInstance()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=500, help="steps per timed block (default 500)")
    parser.add_argument("--repeat", type=int, default=5, help="timed blocks (default 5)")
    parser.add_argument("--warmup", type=float, default=3.0, help="simulated start-up time not timed [s] (default 3)")
    args = parser.parse_args(argv)
    warmup = int(round(args.warmup / STEP_S))
    n_total = warmup + args.steps * args.repeat
    cases = variants()
    info, runners, inputs = {}, {}, {}
    with tempfile.TemporaryDirectory(prefix="dtcosim_bench_size_") as tmp:
        for i, (name, dt) in enumerate(cases.items()):
            a = Assembly(dt, cut_at_generator=True)
            info[name] = (a.n_dof, a.n_mesh, dt.ratio)
            rows, initial = reference_inputs(dt, n_total)
            inputs[name] = rows.tolist()
            path = build_fmu("Gearbox", Path(tmp) / f"v{i}", drivetrain=dt, origin=f"benchmark variant {name}").path
            runners[name] = Stepper(path, initial, f"v{i}")
            runners[name].run(inputs[name][:warmup], 0)
        cpu = {name: [] for name in cases}
        for r in range(args.repeat):
            lo = warmup + r * args.steps
            for name, runner in runners.items():
                cpu[name].append(runner.run(inputs[name][lo: lo + args.steps], lo) / args.steps * 1e6)
        for runner in runners.values():
            runner.close()
    base = statistics.median(cpu["table6"])
    base_dof = info["table6"][0]
    print(f"Gearbox FMU, setReal(4) + doStep + getReal(1) at H = {STEP_S * 1e3:g} ms, CPU time per step, median of "
          f"{args.repeat} blocks of {args.steps} steps after {args.warmup:g} s; ratios to the Table 6 gearbox of this run")
    print(f"  {'variant':<20}{'dof':>5}{'meshes':>8}{'us/step':>10}{'cost ratio':>12}{'dof ratio':>11}"
          f"{'cost/dof ratio':>16}  blocks [us]")
    for name in cases:
        n_dof, n_mesh, _ = info[name]
        med = statistics.median(cpu[name])
        cost, dof = med / base, n_dof / base_dof
        print(f"  {name:<20}{n_dof:>5}{n_mesh:>8}{med:>10.1f}{cost:>12.3f}{dof:>11.3f}{cost / dof:>16.3f}  "
              + ", ".join(f"{x:.0f}" for x in cpu[name]))
    worst = max(statistics.median(cpu[n]) / base / (info[n][0] / base_dof) for n in cases if info[n][0] > base_dof)
    print(f"  largest (cost ratio / dof ratio) among the variants with more dof than Table 6: {worst:.3f} "
          "(<= 1: the cost grows no faster than the number of degrees of freedom; blocks differ by ~10 % "
          "on this shared machine)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
