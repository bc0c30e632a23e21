"""Small real pythonfmu FMUs for testing the master (built by the tests themselves).

Each slave lives in its own module name (pythonfmu shares modules by name inside
one process) and balances pythonfmu 0.7's extra release of the module namespace
(see HEADER). After building, the modelDescription is patched the way the
project's FMUs are: state outputs declare ``dependencies=""`` (no direct
feedthrough) unless the toy is meant to have feedthrough, and units are added.

Toys
----
ToySine        no inputs; outputs y = amplitude sin(2 pi f t) and t_seen (last doStep start)
ToyIntegrator  input u; outputs x (x' = u, exact for held u), u_seen, t_seen; parameter x0
ToyGain        input u; output y = gain u (direct feedthrough: no dependencies attribute)
ToyPass        input u; output y = u, read when asked (direct feedthrough declared: dependencies on u)
ToyAdder       inputs u1, u2; output y = gain u1 + u2 (direct feedthrough: no dependencies attribute)
ToyMassA       mass on a wall spring, input force F; outputs x, v (exact step for held F)
ToyMassB       mass coupled to A by a spring-damper, inputs xa, va; outputs F (force on A), x, v
ToyFailer      output y = t; fails at t >= fail_at (mode 0: discard, 1: exception, 2: NaN output)
ToyInit        parameter p0 (initial value); output y = p0 + u_start; input u
ToyTyped       no inputs; outputs n (Integer: steps done), odd (Boolean: n odd), label (String "step n, ...")
ToyGenerator   a third-party generator rotor: input shaft_torque; outputs omega, phi and a force-named
               output F_x (= shaft_torque / 1 m); parameters inertia, counter_torque, initial_speed
ToyGearbox     a third-party gearbox whose names mislead: F_x [N.m] = 2000 + amplitude sin(2 pi t) (its shaft
               torque; amplitude 1000), shaft1.torque [N] = 500 cos(2 pi t) (a contact force), at the step's end
"""

from __future__ import annotations

import re
import shutil
import textwrap
import zipfile
from pathlib import Path

HEADER = """
import math
from pythonfmu import Fmi2Slave, Fmi2Causality, Fmi2Variability, Real, Integer, Boolean, String

# pythonfmu 0.7's C wrapper executes this module again for each new instance and then releases
# a reference to its namespace that it never took; keep one per execution, or the namespace is
# freed while still in use and the process crashes at exit (same fix as fmus.build's entry script)
_namespace_refs = globals().setdefault("_namespace_refs", [])
_namespace_refs.append(globals())
"""

SOURCES = {
    "ToySine": """
class ToySine(Fmi2Slave):
    def __init__(self, **kw):
        super().__init__(**kw)
        self.amplitude = 1.0
        self.frequency = 1.0
        self.y = 0.0
        self.t_seen = -1.0
        self.register_variable(Real("amplitude", causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable))
        self.register_variable(Real("frequency", causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable))
        self.register_variable(Real("y", causality=Fmi2Causality.output))
        self.register_variable(Real("t_seen", causality=Fmi2Causality.output))
    def exit_initialization_mode(self):
        self.y = 0.0
    def do_step(self, t, h):
        self.t_seen = t
        self.y = self.amplitude * math.sin(2 * math.pi * self.frequency * (t + h))
        return True
""",
    "ToyIntegrator": """
class ToyIntegrator(Fmi2Slave):
    def __init__(self, **kw):
        super().__init__(**kw)
        self.x0 = 0.0
        self.u = 0.0
        self.x = 0.0
        self.u_seen = 0.0
        self.t_seen = -1.0
        self.register_variable(Real("x0", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed))
        self.register_variable(Real("u", causality=Fmi2Causality.input))
        self.register_variable(Real("x", causality=Fmi2Causality.output))
        self.register_variable(Real("u_seen", causality=Fmi2Causality.output))
        self.register_variable(Real("t_seen", causality=Fmi2Causality.output))
    def exit_initialization_mode(self):
        self.x = self.x0
    def do_step(self, t, h):
        self.t_seen = t
        self.u_seen = self.u
        self.x += self.u * h
        return True
""",
    "ToyGain": """
class ToyGain(Fmi2Slave):
    def __init__(self, **kw):
        super().__init__(**kw)
        self.gain = 2.0
        self.u = 0.0
        self.y = 0.0
        self.register_variable(Real("gain", causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable))
        self.register_variable(Real("u", causality=Fmi2Causality.input))
        self.register_variable(Real("y", causality=Fmi2Causality.output, getter=lambda: self.gain * self.u))
    def do_step(self, t, h):
        return True
""",
    "ToyPass": """
class ToyPass(Fmi2Slave):
    def __init__(self, **kw):
        super().__init__(**kw)
        self.u = 0.0
        self.register_variable(Real("u", causality=Fmi2Causality.input))
        self.register_variable(Real("y", causality=Fmi2Causality.output, getter=lambda: self.u))
    def do_step(self, t, h):
        return True
""",
    "ToyAdder": """
class ToyAdder(Fmi2Slave):
    # y = gain * u1 + u2, computed when read (direct feedthrough; like pythonfmu 0.7, no declared dependencies)
    def __init__(self, **kw):
        super().__init__(**kw)
        self.gain = 1.0
        self.u1 = 0.0
        self.u2 = 0.0
        self.register_variable(Real("gain", causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable))
        self.register_variable(Real("u1", causality=Fmi2Causality.input))
        self.register_variable(Real("u2", causality=Fmi2Causality.input))
        self.register_variable(Real("y", causality=Fmi2Causality.output,
                                    getter=lambda: self.gain * self.u1 + self.u2))
    def do_step(self, t, h):
        return True
""",
    "ToyMassA": """
class ToyMassA(Fmi2Slave):
    # m x'' = -k x - c x' + F, F held over the step; exact step by matrix exponential
    def __init__(self, **kw):
        super().__init__(**kw)
        self.m = 1.0
        self.k = 100.0
        self.c = 0.5
        self.x0 = 0.1
        self.F = 0.0
        self.x = 0.0
        self.v = 0.0
        for n in ("m", "k", "c", "x0"):
            self.register_variable(Real(n, causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed))
        self.register_variable(Real("F", causality=Fmi2Causality.input))
        self.register_variable(Real("x", causality=Fmi2Causality.output))
        self.register_variable(Real("v", causality=Fmi2Causality.output))
    def exit_initialization_mode(self):
        self.x = self.x0
        self.v = 0.0
    def do_step(self, t, h):
        import numpy as np
        from scipy.linalg import expm
        A = np.array([[0.0, 1.0, 0.0], [-self.k / self.m, -self.c / self.m, self.F / self.m], [0.0, 0.0, 0.0]])
        y = expm(A * h) @ np.array([self.x, self.v, 1.0])
        self.x, self.v = float(y[0]), float(y[1])
        return True
""",
    "ToyMassB": """
class ToyMassB(Fmi2Slave):
    # m x'' = -k (x - xa) - c (v - va); force on A: F = k (x - xa) + c (v - va); xa, va extrapolated linearly
    def __init__(self, **kw):
        super().__init__(**kw)
        self.m = 0.5
        self.k = 50.0
        self.c = 0.2
        self.xa = 0.0
        self.va = 0.0
        self.x = 0.0
        self.v = 0.0
        self.F = 0.0
        for n in ("m", "k", "c"):
            self.register_variable(Real(n, causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed))
        self.register_variable(Real("xa", causality=Fmi2Causality.input))
        self.register_variable(Real("va", causality=Fmi2Causality.input))
        self.register_variable(Real("F", causality=Fmi2Causality.output))
        self.register_variable(Real("x", causality=Fmi2Causality.output))
        self.register_variable(Real("v", causality=Fmi2Causality.output))
    def exit_initialization_mode(self):
        self.F = self.k * (self.x - self.xa) + self.c * (self.v - self.va)
    def do_step(self, t, h):
        import numpy as np
        from scipy.linalg import expm
        k, c, m = self.k, self.c, self.m
        # state [x, v, xa_rel, 1]: xa(t) = xa + va tau
        A = np.array([[0, 1, 0, 0], [-k / m, -c / m, k / m, c * self.va / m], [0, 0, 0, self.va], [0, 0, 0, 0]], dtype=float)
        y = expm(A * h) @ np.array([self.x, self.v, self.xa, 1.0])
        self.x, self.v = float(y[0]), float(y[1])
        xa1 = self.xa + self.va * h
        self.F = k * (self.x - xa1) + c * (self.v - self.va)
        return True
""",
    "ToyFailer": """
class ToyFailer(Fmi2Slave):
    def __init__(self, **kw):
        super().__init__(**kw)
        self.fail_at = 1e9
        self.mode = 0
        self.u = 0.0
        self.y = 0.0
        self.register_variable(Real("fail_at", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed))
        self.register_variable(Integer("mode", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed))
        self.register_variable(Real("u", causality=Fmi2Causality.input))
        self.register_variable(Real("y", causality=Fmi2Causality.output))
    def do_step(self, t, h):
        if t >= self.fail_at - 1e-12:
            if self.mode == 0:
                from pythonfmu.enums import Fmi2Status
                self.log("solver failed to converge", Fmi2Status.discard)
                return False
            raise RuntimeError(f"toy failure at t={t}")
        self.y = t + h + self.u
        return True
""",
    "ToyInit": """
class ToyInit(Fmi2Slave):
    def __init__(self, **kw):
        super().__init__(**kw)
        self.p0 = 0.0
        self.u = 0.0
        self.y = 0.0
        self.register_variable(Real("p0", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed))
        self.register_variable(Real("u", causality=Fmi2Causality.input))
        self.register_variable(Real("y", causality=Fmi2Causality.output, getter=lambda: self.p0 + self.u_start))
        self.u_start = 0.0
    def exit_initialization_mode(self):
        self.u_start = self.u
    def do_step(self, t, h):
        return True
""",
    "ToyGenerator": """
class ToyGenerator(Fmi2Slave):
    def __init__(self, **kw):
        super().__init__(**kw)
        self.inertia = 151.0
        self.counter_torque = 25400.0
        self.initial_speed = 0.0
        self.shaft_torque = 0.0
        self.omega = 0.0
        self.phi = 0.0
        self.F_x = 0.0
        for name in ("inertia", "counter_torque", "initial_speed"):
            self.register_variable(Real(name, causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed))
        self.register_variable(Real("shaft_torque", causality=Fmi2Causality.input))
        for name in ("omega", "phi", "F_x"):
            self.register_variable(Real(name, causality=Fmi2Causality.output))
    def exit_initialization_mode(self):
        self.omega = self.initial_speed
        self.phi = 0.0
    def do_step(self, t, h):
        alpha = (self.shaft_torque - self.counter_torque) / self.inertia
        self.phi += self.omega * h + 0.5 * alpha * h * h
        self.omega += alpha * h
        self.F_x = self.shaft_torque / 1.0
        return True
""",
    "ToyGearbox": """
class ToyGearbox(Fmi2Slave):
    def __init__(self, **kw):
        super().__init__(**kw)
        self.amplitude = 1000.0
        self.F_x = 2000.0
        self.force = 500.0
        self.register_variable(Real("amplitude", causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed))
        self.register_variable(Real("F_x", causality=Fmi2Causality.output))
        self.register_variable(Real("shaft1.torque", causality=Fmi2Causality.output, getter=lambda: self.force))
    def do_step(self, t, h):
        self.F_x = 2000.0 + self.amplitude * math.sin(2 * math.pi * (t + h))
        self.force = 500.0 * math.cos(2 * math.pi * (t + h))
        return True
""",
    "ToyTyped": """
class ToyTyped(Fmi2Slave):
    def __init__(self, **kw):
        super().__init__(**kw)
        self.n = 0
        self.odd = False
        self.label = "step 0"
        self.register_variable(Integer("n", causality=Fmi2Causality.output))
        self.register_variable(Boolean("odd", causality=Fmi2Causality.output))
        self.register_variable(String("label", causality=Fmi2Causality.output))
    def do_step(self, t, h):
        self.n += 1
        self.odd = self.n % 2 == 1
        self.label = f'step {self.n}, "quoted", comma'
        return True
""",
}

#: toys whose outputs depend directly on their inputs (no dependencies attribute added)
FEEDTHROUGH = {"ToyGain", "ToyAdder", "ToyInit"}
#: toys that declare their outputs' direct dependencies: output -> the inputs it depends on
DECLARED = {"ToyPass": {"y": ("u",)}}

UNITS = {("ToyMassA", "x"): "m", ("ToyMassA", "v"): "m/s", ("ToyMassB", "F"): "N", ("ToyGearbox", "F_x"): "N.m",
         ("ToyGearbox", "shaft1.torque"): "N"}


def _patch_model_description(fmu: Path, model: str) -> None:
    """Add ``dependencies=""`` to the outputs (unless feedthrough) and a few units."""
    tmp = fmu.with_suffix(".tmp")
    with zipfile.ZipFile(fmu) as zin, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                xml = data.decode("utf-8")
                if model in DECLARED:
                    index = {n: str(i + 1) for i, n in enumerate(re.findall(r'<ScalarVariable name="([^"]+)"', xml))}
                    for out, inputs in DECLARED[model].items():
                        deps = " ".join(index[i] for i in inputs)
                        xml = xml.replace(f'<Unknown index="{index[out]}"/>',
                                          f'<Unknown index="{index[out]}" dependencies="{deps}"/>')
                elif model not in FEEDTHROUGH:
                    xml = re.sub(r'<Unknown index="(\d+)"\s*/>', r'<Unknown index="\1" dependencies=""/>', xml)
                for (m, var), unit in UNITS.items():
                    if m == model:
                        xml = re.sub(rf'(<ScalarVariable name="{re.escape(var)}"[^>]*>\s*<Real)', rf'\1 unit="{unit}"', xml)
                data = xml.encode("utf-8")
            zout.writestr(item, data)
    tmp.replace(fmu)


def build_toys(out_dir: Path, names=None) -> dict[str, Path]:
    """Build the toy FMUs into ``out_dir``; returns ``{model name: fmu path}``."""
    from pythonfmu.builder import FmuBuilder

    out_dir = Path(out_dir)
    src_dir = out_dir / "src"
    src_dir.mkdir(parents=True, exist_ok=True)
    out = {}
    for name in names or SOURCES:
        script = src_dir / f"{name.lower()}_slave.py"
        script.write_text(HEADER + textwrap.dedent(SOURCES[name]))
        fmu = Path(FmuBuilder.build_FMU(script, dest=out_dir))
        _patch_model_description(fmu, name)
        out[name] = fmu
    shutil.rmtree(src_dir / "__pycache__", ignore_errors=True)
    return out
