"""Run an SSP in ecos through its Python API (PyPI ``ecospy``) at full double precision.

    python ecos_ssp.py REQUEST.json OUT.npz

``REQUEST.json``: ``{"ssp", "step", "steps", "parameter_set" (or null), "record": ["comp.var", ...],
"parameters": {"comp.var": value, ...}}``. ``OUT.npz``: ``time_s``, one array per recorded
Real (``v0``, ``v1``, ...) sampled after ``init`` and after every step, and ``parameters``
(JSON): the value ecos reports for each requested parameter after ``init`` (what it applied).
In a Python process the pythonfmu FMUs find libpython's symbols: no preload is needed.
"""

from __future__ import annotations

import json
import os
import sys

import numpy as np
from ecospy.EcosSimulation import EcosSimulation


def main(request_path: str, out_path: str) -> int:
    request = json.loads(open(request_path).read())
    sim = EcosSimulation(ssp_path=request["ssp"], step_size=request["step"])
    sim.init(parameter_set=request["parameter_set"])

    def ident(name: str) -> str:
        comp, _, var = name.partition(".")
        return f"{comp}::{var}"

    applied = {}
    for name, value in request["parameters"].items():
        if isinstance(value, bool):
            applied[name] = sim.get_bool(ident(name))
        elif isinstance(value, int):
            applied[name] = sim.get_integer(ident(name))
        elif isinstance(value, float):
            applied[name] = sim.get_real(ident(name))
        else:
            applied[name] = sim.get_string(ident(name))
    times = [sim.get_time()]
    samples = [[sim.get_real(ident(v)) for v in request["record"]]]
    for _ in range(request["steps"]):
        sim.step(1)
        times.append(sim.get_time())
        samples.append([sim.get_real(ident(v)) for v in request["record"]])
    sim.terminate()
    data = np.array(samples)
    np.savez(out_path, time_s=np.array(times), parameters=json.dumps(applied),
             **{f"v{i}": data[:, i] for i in range(len(request["record"]))})
    sim.free()
    return 0


if __name__ == "__main__":
    status = main(*sys.argv[1:])
    sys.stdout.flush()
    sys.stderr.flush()
    # end without the interpreter's teardown, as dtcosim's own commands do: ecos's FMU libraries meet pythonfmu
    # 0.7's exit-time use-after-free there (an occasional "corrupted double-linked list" abort after the results
    # were written; docs/fmus.md, "ecos"), which is not what this driver tests
    os._exit(status)
