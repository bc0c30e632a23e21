"""Initialisation of a system's FMUs: sweeps in dependency order until the transferred values stop changing.

All FMUs are in initialisation mode with their scenario parameter values set. The
master then sweeps the components in :attr:`~orchestrator.cosim.resolved.ResolvedSystem.init_order`
(connections and ``[[initial]]`` bindings; the paper's system: wind, gearbox,
generator), setting each component's connected inputs and bound parameters from
its sources' current outputs (read in initialisation mode): wind ``omega(t0)`` ->
gearbox ``omega_rotor`` -> gearbox ``omega_out`` -> generator initial speed.
Sweeps repeat until no transferred value changes (a fixed point; feedback loops
need one extra sweep; iterated algebraic loops converge within their tolerance),
then every FMU exits initialisation mode.
"""

from __future__ import annotations

import math
from typing import Mapping

from ..errors import InitializationError
from .fmi_runtime import FmuInstance
from .resolved import ResolvedSystem

#: maximum initialisation sweeps beyond the number of components
EXTRA_INIT_SWEEPS = 2


def initialise(system: ResolvedSystem, instances: Mapping[str, FmuInstance],
               transferred: bool = False) -> dict[str, float]:
    """Sweep until the transferred values are a fixed point, then exit initialisation mode.

    Parameters
    ----------
    transferred : bool
        Return every transferred value (connected inputs too), not only the bindings.

    Returns
    -------
    dict of str -> float
        ``{"component.parameter": value}`` for every ``[[initial]]`` binding (with
        ``transferred``: also ``{"component.input": value}`` for every connected input).

    Raises
    ------
    InitializationError
        A transferred value that is not finite, or no fixed point within the sweep limit.
    """
    sc = system.scenario
    sim = sc.simulation
    t0 = sim.start_s
    links = [(c.source, c.target, system.loop_transformation(c)) for c in sc.connections] \
        + [(b.source, b.target, None) for b in sc.initial]
    incoming: dict[str, list] = {name: [] for name in system.init_order}
    for src, dst, transform in links:
        incoming[dst.component].append((src, dst, transform))
    last: dict[str, float] = {}
    max_sweeps = len(system.init_order) + EXTRA_INIT_SWEEPS
    # iterated algebraic loops: converged within the loop tolerance (else: exactly), within their sweep limit
    loops = bool(system.algebraic_loops)
    tolerance = sim.loop_tolerance if loops else 0.0
    if loops:
        max_sweeps = max(max_sweeps, sim.loop_max_iterations)
    changed: list[str] = []
    for _ in range(max_sweeps):
        changed = []
        for name in system.init_order:
            if not incoming[name]:
                continue
            values = {}
            for src, dst, transform in incoming[name]:
                v = instances[src.component].get_values([src.variable], t0)[0]
                if isinstance(transform, dict):
                    v = type(v)(transform.get(int(v), int(v)))
                elif transform is not None:
                    v = transform.apply(v)
                if isinstance(v, float) and not math.isfinite(v):
                    raise InitializationError(f"initialisation: {src} = {v!r} at t = {t0:g} s (needed by {dst})")
                key = str(dst)
                previous = last.get(key)
                if previous != v and not (loops and isinstance(v, float) and isinstance(previous, float)
                                          and abs(v - previous) <= tolerance * max(1.0, abs(v))):
                    changed.append(key)
                last[key] = v
                values[dst.variable] = v
            instances[name].set_values(values, t0)
        if not changed:
            break
    else:
        hint = (" (simulation.loop_max_iterations; an algebraic loop converges only where its gain is below 1 in "
                "magnitude)") if loops else ""
        raise InitializationError(
            f"initialisation did not reach a fixed point after {max_sweeps} sweeps{hint}; still changing: "
            f"{', '.join(changed)}"
        )
    for name in system.init_order:
        instances[name].exit_initialization(t0)
    return dict(last) if transferred else bound_values(system, last)


def bound_values(system: ResolvedSystem, values: Mapping[str, float]) -> dict[str, float]:
    """The ``[[initial]]`` bindings' values among ``values`` (``{"component.parameter": value}``)."""
    bound = {str(b.target) for b in system.scenario.initial}
    return {k: v for k, v in values.items() if k in bound}
