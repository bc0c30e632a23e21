"""The three dtcosim FMUs connected in libcosim (C++ FMI host) through libcosimpy.

libcosim loads the FMUs' shared libraries itself; pythonfmu's library needs
the Python runtime's symbols, so run this with libpython preloaded::

    LD_PRELOAD=$(python -c "import sysconfig as s; print(s.get_config_var('LIBDIR') + '/' + s.get_config_var('LDLIBRARY'))") \\
        python libcosim_run.py FMU_DIR T_END H INITIAL_GENERATOR_SPEED OUT.npz

Connections: WindSource.omega/phi -> Gearbox.omega_rotor/phi_rotor,
GeneratorRotor.omega/phi -> Gearbox.omega_gen/phi_gen, Gearbox.shaft_torque ->
GeneratorRotor.shaft_torque. The generator's initial speed is a parameter
(libcosim has no initialisation-mode propagation into parameters); the
Gearbox's generator inputs get the same start values. libcosim's fixed-step
algorithm exchanges values after all FMUs stepped (Jacobi).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from fmpy import read_model_description
from libcosimpy._internal import get_last_error_message
from libcosimpy.CosimEnums import CosimVariableType
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave


def value_references(path: Path) -> dict[str, int]:
    return {v.name: v.valueReference for v in read_model_description(str(path)).modelVariables}


def check(ok: bool, what: str) -> None:
    if not ok:
        raise RuntimeError(f"libcosim: {what} failed: {get_last_error_message()}")


def run(fmu_dir: Path, t_end: float, step: float, initial_speed: float) -> dict[str, np.ndarray]:
    log_output_level(CosimLogLevel.WARNING)
    paths = {name: fmu_dir / f"{name}.fmu" for name in ("WindSource", "Gearbox", "GeneratorRotor")}
    vr = {name: value_references(p) for name, p in paths.items()}
    execution = CosimExecution.from_step_size(step_size=int(round(step * 1e9)))
    index = {}
    for name, path in paths.items():
        index[name] = execution.add_local_slave(CosimLocalSlave(fmu_path=str(path), instance_name=name))
        check(index[name] >= 0, f"adding {name}")
    wind, gearbox, generator = index["WindSource"], index["Gearbox"], index["GeneratorRotor"]
    for src, out, dst, inp in (
        (wind, "omega", gearbox, "omega_rotor"), (wind, "phi", gearbox, "phi_rotor"),
        (generator, "omega", gearbox, "omega_gen"), (generator, "phi", gearbox, "phi_gen"),
        (gearbox, "shaft_torque", generator, "shaft_torque"),
    ):
        src_name = [k for k, v in index.items() if v == src][0]
        dst_name = [k for k, v in index.items() if v == dst][0]
        check(execution.connect_real_variables(src, vr[src_name][out], dst, vr[dst_name][inp]) == 0,
              f"connecting {src_name}.{out} -> {dst_name}.{inp}")
    check(execution.real_initial_value(generator, vr["GeneratorRotor"]["initial_speed"], initial_speed),
          "setting the generator's initial speed")
    check(execution.real_initial_value(gearbox, vr["Gearbox"]["omega_gen"], initial_speed),
          "setting the gearbox's omega_gen start value")
    n_steps = int(round(t_end / step))
    observer = CosimObserver.create_time_series(buffer_size=n_steps + 10)
    check(execution.add_observer(observer), "adding the observer")
    recorded = {"GeneratorRotor.omega": (generator, vr["GeneratorRotor"]["omega"]),
                "Gearbox.shaft_torque": (gearbox, vr["Gearbox"]["shaft_torque"]),
                "WindSource.omega": (wind, vr["WindSource"]["omega"])}
    for slave, ref in recorded.values():
        check(observer.start_time_series(slave, ref, CosimVariableType.REAL), "starting a time series")
    check(execution.simulate_until(target_time=int(round(t_end * 1e9))), "simulate_until")
    out = {}
    for name, (slave, ref) in recorded.items():
        times_ns, steps, values = observer.time_series_real_samples(slave, ref, from_step=0, sample_count=n_steps + 1)
        out[name] = np.array(values)
        out["time"] = np.array(times_ns) * 1e-9
    return out


if __name__ == "__main__":
    fmu_dir, t_end, step, speed, out_path = Path(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), sys.argv[5]
    np.savez(out_path, **run(fmu_dir, t_end, step, speed))
    print("libcosim run finished")
