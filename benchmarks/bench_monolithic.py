"""Benchmark: the 60 s Table 7 case with the monolithic reference solver.

Prints the median wall time of the solver (LSODA with the analytic Jacobian)
and, as a baseline measured in the same process, the same solver with a
finite-difference Jacobian; target: under 1 s on the 2-core machine.

Run: ``python benchmarks/bench_monolithic.py [--repeat N]``
"""

from __future__ import annotations

import one_blas_thread  # noqa: F401 - first: one BLAS thread (CPU time without spinning workers)

import argparse
import statistics
import time

from components.model.presets import table6_gearbox
from components.model.wind import RotorSpeedProcess, WindParameters
from components.reference.solver import MonolithicSystem, simulate_monolithic


def _run(analytic: bool) -> tuple[float, dict]:
    dt = table6_gearbox()
    wind = RotorSpeedProcess(WindParameters())
    original = MonolithicSystem.jacobian
    if not analytic:
        MonolithicSystem.jacobian = None  # odeint then builds the Jacobian by finite differences
    try:
        from components.reference import solver as reference

        if not analytic:
            real_odeint = reference.odeint

            def odeint_fd(*args, **kwargs):
                kwargs["Dfun"] = None
                return real_odeint(*args, **kwargs)

            reference.odeint = odeint_fd
        start = time.perf_counter()
        result = simulate_monolithic(dt, wind, 60.0)
        wall = time.perf_counter() - start
    finally:
        MonolithicSystem.jacobian = original
        if not analytic:
            reference.odeint = real_odeint
    assert result.complete, result.message
    return wall, result.info


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    analytic = [_run(True) for _ in range(args.repeat)]
    baseline = [_run(False) for _ in range(max(1, args.repeat // 2))]
    t_a = statistics.median(w for w, _ in analytic)
    t_b = statistics.median(w for w, _ in baseline)
    print(f"60 s Table 7 case, monolithic LSODA, median of {len(analytic)} runs")
    print(f"  analytic Jacobian        : {t_a:7.3f} s  ({analytic[0][1]['rhs_calls']} rhs, {analytic[0][1]['jacobian_calls']} jac)")
    print(f"  finite-difference (base) : {t_b:7.3f} s  ({baseline[0][1]['rhs_calls']} rhs)")
    print(f"  speed-up analytic / baseline: {t_b / t_a:5.2f} x")
    print(f"  target < 1 s: {'met' if t_a < 1.0 else 'NOT met'} ({t_a:.3f} s)")


if __name__ == "__main__":
    main()
