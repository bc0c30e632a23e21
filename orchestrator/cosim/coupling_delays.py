"""What a stepping order means for each connection: the communication point its value belongs to, and the delays.

Step ``k`` takes every FMU from ``t_k`` to ``t_{k+1}``. FMI 2 reads an input set
before ``fmi2DoStep(t_k, H)`` as its value at ``t_k``, held over the step. What a
connection ``P.y -> C.u`` actually carries in step ``k``:

* ``y`` does not depend directly on an input of P (a state output): P's value after
  its latest step, ``t_{k+1}`` if Gauss-Seidel stepped P before C in this step, else
  ``t_k`` (Jacobi: always ``t_k``);
* ``y`` depends directly on connected inputs of P (ModelStructure/Outputs
  ``dependencies``): ``y`` was computed from the inputs P was given for its latest
  step. Stepped before C, that is this step's: C receives what P's sources gave P
  (a pass-through is transparent). Stepped after C (or with Jacobi), P's latest step
  is the previous one: C receives its inputs' values of one communication point
  earlier than P's sources hold them, ``t_{k-1}`` for a source of ``t_k``. That
  is a **one-step delay**: a value older than the communication point the step
  starts from. Chains add up.

A **feedback loop** (components that drive each other) cannot be stepped with
new values in both directions: Gauss-Seidel gives the members stepped first their
partners' values of ``t_k`` and the later ones the values of ``t_{k+1}``. For
outputs without direct dependencies the loop is not algebraic and that is the
deliberate explicit coupling of the loop (the paper's gearbox <-> generator: the
Gearbox's interface model integrates the generator inertia over the step against
the counter torque of ``t_k``), but it is a one-step delay in one direction, so
the run says where, once per loop.

:func:`coupling_delays` lists both kinds for a resolved order, each with the
connections and why (``ResolvedSystem.delays``: ``coupling_delays`` in
``summary.json``, printed by ``dtcosim run --check``); the delays of pass-through
outputs are also ``ResolvedSystem.notes``, which every ``dtcosim run`` prints (a
coupling error nobody chose), while a loop's lagging direction, its deliberate
explicit coupling, is not repeated on every run. Iterated algebraic loops
(``algebraic_loops = "iterate"``) are solved at every communication point and
carry no delay inside the loop.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterable, Mapping, Sequence

from .graph import direct_inputs, strongly_connected

FEEDTHROUGH, LOOP = "feedthrough", "loop"
GAUSS_SEIDEL = "gauss-seidel"


def _component(variable: str) -> str:
    return variable.partition(".")[0]


def _point(offset: int) -> str:
    """``t_{k+1}``, ``t_k``, ``t_{k-1}``, ... for an offset in steps from ``t_k``."""
    return "t_k" if offset == 0 else f"t_{{k{offset:+d}}}"


@dataclass(frozen=True)
class CouplingDelay:
    """Connections from one component to another that lag one (or more) communication steps.

    Attributes
    ----------
    kind : {"feedthrough", "loop"}
        ``feedthrough``: outputs that depend directly on inputs reach ``target`` computed
        from inputs one step older than their sources hold (a value older than ``t_k``);
        ``loop``: the back direction of a Gauss-Seidel feedback loop (values of ``t_k``,
        one step behind the ``t_{k+1}`` values the partner receives).
    source, target : str
        The components.
    connections : tuple of str
        ``"source.output -> target.input"``.
    received : str
        The communication point the values belong to in step ``k`` (``"t_k"``, ``"t_{k-1}"``, ...).
    why : str
        The reason, in words.
    undeclared : bool
        Every output on these connections lacks declared dependencies (FMI 2: depends on every input).
    """

    kind: str
    source: str
    target: str
    connections: tuple[str, ...]
    received: str
    why: str
    undeclared: bool = False

    @property
    def note(self) -> str:
        """One line for ``dtcosim run`` and ``summary.json``."""
        return f"one-step delay on {', '.join(self.connections)} (values of {self.received}): {self.why}"

    def as_dict(self) -> dict[str, Any]:
        """The ``summary.json`` entry."""
        return {"kind": self.kind, "from": self.source, "to": self.target, "connections": list(self.connections),
                "received": self.received, "why": self.why}


def received_points(order: Sequence[str], algorithm: str, connections: Sequence[tuple[str, str]],
                    direct: Mapping[str, Sequence[str]]) -> dict[tuple[str, str], int]:
    """For each connection, the communication point (steps from ``t_k``) of the value it carries in step ``k``.

    Parameters
    ----------
    order : sequence of str
        Stepping order.
    algorithm : str
        ``"gauss-seidel"`` or ``"jacobi"``.
    connections : sequence of (str, str)
        ``("comp.output", "comp.input")``.
    direct : mapping of str -> sequence of str
        The connected inputs each output depends on directly (:func:`orchestrator.cosim.graph.direct_inputs`).
    """
    slot = {c: i for i, c in enumerate(order)}
    gauss_seidel = algorithm == GAUSS_SEIDEL
    producer = {inp: out for out, inp in connections}
    memo: dict[tuple[str, str], int] = {}

    def point(out: str, inp: str, seen: frozenset) -> int:
        key = (out, inp)
        if key in memo:
            return memo[key]
        ahead = gauss_seidel and slot[_component(out)] < slot[_component(inp)]
        if out not in direct or key in seen:  # a state output (a cycle only through a loop the master iterates)
            value = 1 if ahead else 0
        else:  # computed from the inputs of the source's latest step: this one if it stepped first
            used = min(point(producer[i], i, seen | {key}) for i in direct[out])
            value = used if ahead else used - 1
        memo[key] = value
        return value

    return {c: point(*c, frozenset()) for c in connections}


def coupling_delays(components: Sequence[str], order: Sequence[str], algorithm: str,
                    connections: Iterable[tuple[str, str]], feedthrough: Mapping[str, Iterable[str]],
                    declared: Mapping[str, Iterable[str]] | None = None, solved: Iterable[str] = (),
                    explicit: bool = False, default_order: Sequence[str] | None = None) -> tuple[CouplingDelay, ...]:
    """Where ``order`` puts a one-step delay on a connection, and why (see the module docstring).

    Parameters
    ----------
    components : sequence of str
        Component names in declaration order.
    order : sequence of str
        The stepping order the run uses.
    algorithm : str
        ``"gauss-seidel"`` or ``"jacobi"``.
    connections : iterable of (str, str)
        ``("comp.output", "comp.input")``.
    feedthrough : mapping of str -> iterable of str
        For each input, the outputs of the same FMU that depend on it directly (outputs without
        declared dependencies on every input, as FMI 2 reads them).
    declared : mapping of str -> iterable of str, optional
        The same, with only the dependencies the model descriptions state (default: ``feedthrough``):
        the delays through undeclared outputs are reported as such.
    solved : iterable of str
        Variables of the algebraic loops the master iterates.
    explicit : bool
        ``order`` is the scenario's ``simulation.order``.
    default_order : sequence of str, optional
        The order from the declared dependencies (suggested where ``order`` is explicit and delays).
    """
    connections = list(connections)
    solved = set(solved)
    direct = direct_inputs(connections, feedthrough, solved)
    stated = direct if declared is None else direct_inputs(connections, declared, solved)
    points = received_points(order, algorithm, connections, direct)
    slot = {c: i for i, c in enumerate(order)}
    gauss_seidel = algorithm == GAUSS_SEIDEL
    out: list[CouplingDelay] = []

    # one-step delays of direct outputs: the source's latest step is the previous one
    late: dict[tuple[str, str], list[tuple[str, str]]] = {}
    for c in connections:
        if c[0] in direct and not (gauss_seidel and slot[_component(c[0])] < slot[_component(c[1])]):
            late.setdefault((_component(c[0]), _component(c[1])), []).append(c)
    for (src, dst), cons in late.items():
        outputs = sorted({o for o, _ in cons})
        on = sorted({i.partition(".")[2] for o in outputs for i in direct[o]})
        undeclared = [o for o in outputs if o not in stated]
        depends = (f"{', '.join(outputs)} {'depends' if len(outputs) == 1 else 'depend'} directly on {src}'s "
                   f"{', '.join(on)}" + (f" ({', '.join(undeclared)} without declared dependencies: FMI 2 reads that "
                                         "as depending on every input; --no-feedthrough COMPONENT.OUTPUT says "
                                         "one does not)" if undeclared else ""))
        if not gauss_seidel:
            why = (f"{depends}; Jacobi sets every input from the values of t_k before any FMU steps, so {src}'s "
                   "outputs still hold its inputs of the previous step (--algorithm gauss-seidel steps "
                   f"{src} before {dst} and passes them in the same step)")
        elif explicit:
            better = f" ({', '.join(default_order)})" if default_order and list(default_order) != list(order) else ""
            why = (f"{depends}, and simulation.order steps {src} after {dst}, so {src}'s outputs still hold its "
                   f"inputs of the previous step; the order from the declared dependencies{better} steps {src} "
                   f"before {dst}")
        else:
            why = (f"{depends}, and {src} cannot be stepped before {dst}: the components feed each other through "
                   "outputs that depend directly on their inputs, so one of them steps before a consumer of its "
                   "outputs")
        received = _point(min(points[c] for c in cons))
        out.append(CouplingDelay(FEEDTHROUGH, src, dst, tuple(f"{o} -> {i}" for o, i in cons), received, why,
                                 undeclared=len(undeclared) == len(outputs)))

    if gauss_seidel:
        out += _loop_delays(components, order, connections, direct, solved, explicit, points)
    return tuple(out)


def _loop_delays(components: Sequence[str], order: Sequence[str], connections: list[tuple[str, str]],
                 direct: Mapping[str, Sequence[str]], solved: set[str], explicit: bool,
                 points: Mapping[tuple[str, str], int]) -> list[CouplingDelay]:
    """One entry per feedback loop: its connections into members stepped before their sources."""
    slot = {c: i for i, c in enumerate(order)}
    rank = {c: i for i, c in enumerate(components)}
    succ: dict[str, set[str]] = {c: set() for c in components}
    for o, i in connections:
        succ[_component(o)].add(_component(i))
    out = []
    for scc in strongly_connected(list(components), {c: sorted(s, key=rank.get) for c, s in succ.items()}):
        if len(scc) < 2:
            continue
        members = set(scc)
        back: dict[tuple[str, str], list[tuple[str, str]]] = {}
        for o, i in connections:
            src, dst = _component(o), _component(i)
            if src in members and dst in members and slot[src] > slot[dst] and o not in direct \
                    and not (o in solved and i in solved):
                back.setdefault((src, dst), []).append((o, i))
        if not back:
            continue
        stepped = sorted(scc, key=slot.get)
        first = ("simulation.order" if explicit else
                 "declaration order" if stepped == sorted(scc, key=rank.get) else "the declared dependencies")
        for (src, dst), cons in sorted(back.items(), key=lambda item: (slot[item[0][1]], slot[item[0][0]])):
            loop = " <-> ".join(stepped) if len(stepped) == 2 else "of " + ", ".join(stepped)
            why = (f"Gauss-Seidel breaks the feedback loop {loop} here: {dst} steps before {src} ({first}) "
                   f"with {src}'s values of t_k, one step behind the t_{{k+1}} values {src} then receives; these "
                   "outputs depend on no input directly, so the loop is not algebraic and the delay is the loop's "
                   "explicit coupling (simulation.order chooses the direction that lags)")
            received = _point(min(points[c] for c in cons))
            out.append(CouplingDelay(LOOP, src, dst, tuple(f"{o} -> {i}" for o, i in cons), received, why))
    return out
