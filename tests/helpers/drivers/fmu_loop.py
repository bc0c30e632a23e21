"""Plain fmpy co-simulation loop over the three dtcosim FMUs (imports nothing from dtcosim).

Used by the tests in-process and in a fresh virtual environment that has
numpy, scipy and fmpy but not dtcosim; also a template for other hosts.

Initialisation (the order the orchestrator uses): WindSource -> omega, phi at
t0; Gearbox inputs from the wind, ``omega_gen = omega_out``, ``phi_gen =
ratio * phi_rotor`` (zero twist); GeneratorRotor ``initial_speed/angle`` from
those; then every FMU exits initialisation mode. With ``init="scenario"`` the
generator angle is left at its default (0) and ``phi_gen`` is that angle, as
``dtcosim run`` initialises the paper scenario (its only initial binding is the
generator's initial speed), and every component gets the parameter values of
``paper-60s.toml`` (read with ``tomllib``; e.g. the Gearbox's solver tolerances),
so the two give the same numbers. Stepping (Gauss-Seidel, step
``H``): the Gearbox steps with the wind and generator motion at ``t``, the
generator steps with the Gearbox's ``shaft_torque``, the wind steps.

Usage: ``python fmu_loop.py FMU_DIR T_END H OUT.npz [zero-twist|scenario]``
"""

from __future__ import annotations

import sys
import tomllib
from ctypes import c_double, c_uint32
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

#: the scenario whose parameter values ``init="scenario"`` applies
PAPER_SCENARIO = Path(__file__).resolve().parents[3] / "orchestrator" / "scenarios" / "paper-60s.toml"
#: recorded signals: (FMU, variable)
RECORDED = (
    ("WindSource", "omega"),
    ("Gearbox", "shaft_torque"),
    ("Gearbox", "omega_out"),
    ("Gearbox", "stage1.F_sp[1]"),
    ("Gearbox", "torque_rotor"),
    ("GeneratorRotor", "omega"),
)


class Instance:
    """One FMU instance with value references by name and fast get/set through the C API."""

    def __init__(self, fmu_path: Path, name: str) -> None:
        md = read_model_description(str(fmu_path))
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.type = {v.name: v.type for v in md.modelVariables}
        self.unzip_dir = extract(str(fmu_path))
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=self.unzip_dir,
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate(loggingOn=True)
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()

    def get(self, *names: str) -> list[float]:
        return self.fmu.getReal([self.vr[n] for n in names])

    def set(self, **values: float) -> None:
        self.fmu.setReal([self.vr[n] for n in values], list(values.values()))

    def set_parameters(self, values: dict[str, float | int | bool]) -> None:
        """Set parameter values of any type the paper scenario uses (Real, Integer, Boolean)."""
        for name, value in values.items():
            if self.type[name] == "Integer":
                self.fmu.setInteger([self.vr[name]], [int(value)])
            elif self.type[name] == "Boolean":
                self.fmu.setBoolean([self.vr[name]], [bool(value)])
            else:
                self.fmu.setReal([self.vr[name]], [float(value)])

    def setter(self, *names: str):
        """Fast setter for fixed value references (pre-built arrays)."""
        vrs = (c_uint32 * len(names))(*[self.vr[n] for n in names])
        buf = (c_double * len(names))()
        fmi2SetReal, component = self.fmu.fmi2SetReal, self.fmu.component

        def set_values(*values: float) -> None:
            buf[:] = values
            fmi2SetReal(component, vrs, len(names), buf)

        return set_values

    def getter(self, *names: str):
        """Fast getter for fixed value references (pre-built arrays)."""
        vrs = (c_uint32 * len(names))(*[self.vr[n] for n in names])
        buf = (c_double * len(names))()
        fmi2GetReal, component = self.fmu.fmi2GetReal, self.fmu.component

        def get_values() -> list[float]:
            fmi2GetReal(component, vrs, len(names), buf)
            return buf[:]

        return get_values


def run(fmu_dir: str | Path, t_end: float, step: float, init: str = "zero-twist") -> dict[str, np.ndarray]:
    """Run the loop; returns ``{"time": ..., "<FMU>.<variable>": ...}`` sampled after each step.

    ``init``: ``"zero-twist"`` (generator angle ``ratio * phi_rotor``) or ``"scenario"`` (as ``dtcosim run``).
    """
    fmu_dir = Path(fmu_dir)
    wind = Instance(fmu_dir / "WindSource.fmu", "wind")
    gearbox = Instance(fmu_dir / "Gearbox.fmu", "gearbox")
    generator = Instance(fmu_dir / "GeneratorRotor.fmu", "generator")
    instances = {"WindSource": wind, "Gearbox": gearbox, "GeneratorRotor": generator}
    if init == "scenario":
        with open(PAPER_SCENARIO, "rb") as f:
            components = tomllib.load(f)["components"]
        for table in components.values():
            instances[Path(table["fmu"]).stem].set_parameters(table.get("parameters", {}))

    omega_rotor, phi_rotor = wind.get("omega", "phi")
    gearbox.set(omega_rotor=omega_rotor, phi_rotor=phi_rotor)
    (omega_out,) = gearbox.get("omega_out")
    ratio = omega_out / omega_rotor
    if init == "scenario":
        generator.set(initial_speed=omega_out)
        gearbox.set(omega_gen=omega_out, phi_gen=generator.get("phi")[0])
    else:
        gearbox.set(omega_gen=omega_out, phi_gen=ratio * phi_rotor)
        generator.set(initial_speed=omega_out, initial_angle=ratio * phi_rotor)
    for inst in instances.values():
        inst.fmu.exitInitializationMode()

    # the paper scenario's connections (the interface model's too: unused inputs with the FMUs' defaults)
    set_gearbox = gearbox.setter("omega_rotor", "phi_rotor", "alpha_rotor", "jerk_rotor", "omega_gen", "phi_gen",
                                 "counter_torque")
    get_torque = gearbox.getter("shaft_torque")
    set_torque = generator.setter("shaft_torque")
    get_wind = wind.getter("omega", "phi", "alpha", "jerk")
    get_generator = generator.getter("omega", "phi", "generator_torque")
    recorded = [(f, v) for f, v in RECORDED if v in instances[f].vr]  # e.g. no F_sp in a parallel-only preset
    recorders = [instances[f].getter(v) for f, v in recorded]

    n_steps = int(round(t_end / step))
    record = np.empty((n_steps + 1, len(recorded) + 1))
    record[0] = [0.0] + [r()[0] for r in recorders]
    for n in range(n_steps):
        t = n * step
        set_gearbox(*get_wind(), *get_generator())
        gearbox.fmu.doStep(t, step)
        set_torque(*get_torque())
        generator.fmu.doStep(t, step)
        wind.fmu.doStep(t, step)
        record[n + 1] = [t + step] + [r()[0] for r in recorders]
    for inst in instances.values():
        inst.fmu.terminate()
        inst.fmu.freeInstance()
    out = {"time": record[:, 0]}
    for k, (f, v) in enumerate(recorded):
        out[f"{f}.{v}"] = record[:, k + 1]
    out["initial_generator_speed"] = np.array(omega_out)
    return out


def loaded_dtcosim_modules() -> list[str]:
    """Top-level modules of this process that come from dtcosim (the FMUs' private packages included)."""
    tops = {name.split(".")[0] for name in sys.modules}
    return sorted(t for t in tops if t.startswith("_dtcosim_") or t in ("components", "fmus", "orchestrator"))


if __name__ == "__main__":
    fmu_dir, t_end, step, out_path = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
    result = run(fmu_dir, t_end, step, *sys.argv[5:6])
    np.savez(out_path, modules=np.array(loaded_dtcosim_modules()), numba_loaded=np.array("numba" in sys.modules),
             **result)
