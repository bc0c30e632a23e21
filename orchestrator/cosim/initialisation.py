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

Before the first sweep the parameter bindings (``[[bindings]]``) are applied: each
bound parameter is set to its source parameter's value, read with ``fmi2GetXXX`` once
every FMU has its start values (FMI 2.0 allows reading only from initialisation mode
on, and setting a parameter with ``initial="exact"`` there), chains in the order the
value flows: the paper's ``gearbox.generator_inertia = generator.inertia``. Nothing
has been computed from the target yet, so the FMU sees one value only.
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
        ``{"component.parameter": value}`` for every ``[[bindings]]`` target and every
        ``[[initial]]`` binding (with ``transferred``: also ``{"component.input": value}``
        for every connected input).

    Raises
    ------
    InitializationError
        A transferred value that is not finite, or no fixed point within the sweep limit.
    """
    sc = system.scenario
    sim = sc.simulation
    t0 = sim.start_s
    bound = apply_bindings(system, instances)
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
    return {**bound, **(dict(last) if transferred else bound_values(system, last))}


def apply_bindings(system: ResolvedSystem, instances: Mapping[str, FmuInstance]) -> dict[str, object]:
    """Set every ``[[bindings]]`` target from its source's value (FMUs in initialisation mode); returns them.

    Raises
    ------
    InitializationError
        A source value that is not a finite number.
    """
    t0 = system.scenario.simulation.start_s
    pending = list(system.scenario.bindings)
    targets = {str(b.target) for b in pending}
    values: dict[str, object] = {}
    while pending:  # a source that is itself bound waits for its own binding
        ready = [b for b in pending if str(b.source) not in targets or str(b.source) in values]
        for b in ready:
            v = instances[b.source.component].get_values([b.source.variable], t0)[0]
            if isinstance(v, float) and not math.isfinite(v):
                raise InitializationError(f"initialisation: {b.source} = {v!r} (bound to {b.target})")
            instances[b.target.component].set_values({b.target.variable: v}, t0)
            values[str(b.target)] = v
        pending = [b for b in pending if b not in ready]
    return values


def bound_values(system: ResolvedSystem, values: Mapping[str, float]) -> dict[str, float]:
    """The values of the ``[[initial]]`` and ``[[bindings]]`` targets among ``values`` (``{"component.parameter": value}``)."""
    bound = {str(b.target) for b in (*system.scenario.initial, *system.scenario.bindings)}
    return {k: v for k, v in values.items() if k in bound}
