"""What the master runs: a scenario whose names have all been checked against its FMUs.

:class:`ResolvedSystem` is the result of :func:`orchestrator.cosim.system.resolve_system`
(which checks); the modules that only read a resolved system (the physics view, the
master, the run's analyses) import it from here, so none of them depends on the checks.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping

from ..inputs.scenario import Scenario, VariableRef
from .coupling_delays import CouplingDelay
from .event_slots import AssignedEvent
from .fmu_interface import FmuInterface, FmuVariable
from .roles import ComponentRole


#: a variable is a signal (a result the statistics describe) by these declarations
SIGNAL_CAUSALITIES = ("output", "local")
SIGNAL_VARIABILITIES = ("continuous", "discrete")


@dataclass(frozen=True)
class RecordedVariable:
    """A variable sampled into the results.

    Attributes
    ----------
    component, variable : str
    value_reference : int
    unit : str
        Unit declared by the FMU ("" if none).
    type : str
        FMI type: ``Real``, ``Integer``, ``Boolean``, ``String`` or ``Enumeration``.
    """

    component: str
    variable: str
    value_reference: int
    unit: str
    type: str = "Real"

    @property
    def column(self) -> str:
        """Result column name ``component.variable``."""
        return f"{self.component}.{self.variable}"


@dataclass(frozen=True)
class ResolvedSystem:
    """A scenario whose names have all been checked against the FMUs.

    Attributes
    ----------
    scenario : Scenario
        The checked scenario; its load events (``[[events]]``) are already written into
        the event-slot parameters of their component (see :mod:`orchestrator.inputs.load_events`).
    fmu_paths : mapping of str -> pathlib.Path
        Absolute FMU file of each component.
    interfaces : mapping of str -> FmuInterface
        Model description of each component's FMU.
    order : tuple of str
        Stepping order (Gauss-Seidel sweep order; Jacobi ignores it).
    init_order : tuple of str
        Order of the initialisation sweeps (connections and initial bindings).
    recorded : tuple of RecordedVariable
        Recorded variables in the order of the record patterns.
    events : tuple of AssignedEvent
        The scenario's load events with the component and slot that apply them.
    roles : mapping of str -> ComponentRole
        Declared role of each component that has one (its FMU's record or the scenario).
    algebraic_loops : tuple of tuple of str
        With ``simulation.algebraic_loops = "iterate"``: the components of each algebraic
        loop, which the master solves by iteration (:mod:`orchestrator.cosim.algebraic_loops`).
    notes : tuple of str
        What the checks accepted with a caveat (a loop through outputs that declare no
        dependencies, run with Jacobi; every one-step delay the stepping order puts on a
        connection); printed by ``dtcosim run`` and kept in the summary.
    delays : tuple of CouplingDelay
        The connections that lag a communication step in this order, and why
        (:mod:`orchestrator.cosim.coupling_delays`); ``coupling_delays`` in the summary.
    """

    scenario: Scenario
    fmu_paths: Mapping[str, Path]
    interfaces: Mapping[str, FmuInterface]
    order: tuple[str, ...]
    init_order: tuple[str, ...]
    recorded: tuple[RecordedVariable, ...]
    events: tuple[AssignedEvent, ...] = ()
    roles: Mapping[str, ComponentRole] = field(default_factory=dict)
    algebraic_loops: tuple[tuple[str, ...], ...] = ()
    notes: tuple[str, ...] = ()
    delays: tuple[CouplingDelay, ...] = ()

    def with_role(self, role: str) -> list[ComponentRole]:
        """The components declared with ``role``, in scenario order."""
        return [r for r in self.roles.values() if r.role == role]

    def loop_transformation(self, con):
        """What the step loop applies on connection ``con`` (:func:`orchestrator.cosim.values.numeric_transformation`)."""
        from .values import numeric_transformation

        return numeric_transformation(con.transformation, self.variable(con.source), self.variable(con.target),
                                      self.interfaces[con.source.component].enumerations,
                                      self.interfaces[con.target.component].enumerations)

    def is_signal(self, component: str, variable: str) -> bool:
        """Whether a variable is a signal by its declaration: causality output or local, variability continuous
        or discrete (not a parameter, a constant or an input; :data:`SIGNAL_CAUSALITIES`)."""
        var = self.interfaces[component].variables[variable]
        return var.causality in SIGNAL_CAUSALITIES and var.variability in SIGNAL_VARIABILITIES

    def variable(self, ref: VariableRef) -> FmuVariable:
        """Model-description entry of a ``component.variable`` reference."""
        return self.interfaces[ref.component].variables[ref.variable]

    def parameter_values(self, component: str) -> dict[str, object]:
        """Effective parameter values of a component: FMU start values overridden by the scenario, and the bound
        parameters' the values of their sources (``[[bindings]]``), as the FMU will have them in the run."""
        iface = self.interfaces[component]
        values = {n: v.start for n, v in iface.variables.items() if v.causality == "parameter"}
        values.update(self.scenario.component(component).parameters)
        for b in self.scenario.bindings:
            if b.target.component == component:
                source = VariableRef.parse(self.scenario.bound_source(b.target), "bindings")
                values[b.target.variable] = self.parameter_values(source.component).get(
                    source.variable, self.variable(source).start)  # a calculatedParameter: its start value
        return values
