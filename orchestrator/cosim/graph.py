"""Connection graphs: stepping order of the components and algebraic-loop detection.

Stepping order
--------------
The component graph has an edge A -> B when an output of A drives an input of B.
Its strongly connected components (Tarjan) are the feedback loops (e.g. gearbox
<-> generator) and the single components outside loops. The default order steps
*receivers before their sources* across loops (reverse topological order of the
strongly connected components) and the members of a loop in declaration order.
With the Gauss-Seidel master a component then receives, from outside its loop,
its sources' values at ``t_k`` (what an input set before ``fmi2DoStep(t_k, H)``
means in FMI 2), and, inside its loop, the newer values of the members stepped
before it. For the paper's system the order is ``gearbox, generator, wind``:
the gearbox gets rotor and generator motion at the same instant ``t_k``, the
generator the shaft torque of the step just computed. Stepping the wind source
first would hand the gearbox the rotor motion at ``t_{k+1}`` next to the
generator motion at ``t_k``; that inconsistency is a first-order coupling error
(docs/orchestrator.md, coupling study).

Direct feedthrough
------------------
An output that depends *directly* on an input (ModelStructure/Outputs
``dependencies``) is computed from the value the input has when it is read: a
pass-through FMU F between W and C (``W.z -> F.u``, ``F.y = g(F.u) -> C.v``) hands
C what W gave F in the same communication step only if F is stepped before C;
stepped after C, F's output still holds the previous step's input and C receives
W's value one step late. :func:`dependency_order` therefore orders the system as
if every such connection ran from F's own sources straight to C (so W and C keep
the relative order they would have if connected directly, a loop through F is a
loop of W and C) and then steps each pass-through FMU immediately before the
first component that consumes its direct outputs (chains of them in the order the
data flows). Without direct dependencies on connected inputs it is
:func:`stepping_order`. What an order means for each connection (the value of
which communication point it receives, where a one-step delay remains) is
:mod:`orchestrator.cosim.coupling_delays`.

Algebraic loops
---------------
A loop is algebraic when every connection on it enters an input that the
receiving FMU's output on the loop depends on *directly* (ModelStructure/Outputs
``dependencies``; an output without the attribute depends on all inputs). The
variable graph has an edge for every connection (output -> input) and for every
direct dependency inside an FMU (input -> output); any cycle in it is an
algebraic loop that a non-iterative fixed-step master cannot resolve; the master
solves them by iteration when a scenario asks (:func:`algebraic_loop_groups`,
:mod:`orchestrator.cosim.algebraic_loops`).
"""

from __future__ import annotations

from typing import Iterable, Mapping, Sequence


def strongly_connected(nodes: Sequence[str], edges: Mapping[str, Iterable[str]]) -> list[list[str]]:
    """Strongly connected components (Tarjan), each as a list of nodes.

    Parameters
    ----------
    nodes : sequence of str
        All nodes (order only affects the order of discovery).
    edges : mapping of str -> iterable of str
        Successors of each node.
    """
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    out: list[list[str]] = []
    counter = 0

    for root in nodes:
        if root in index:
            continue
        # iterative DFS: (node, iterator over successors)
        work = [(root, iter(edges.get(root, ())))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, it = work[-1]
            advanced = False
            for nxt in it:
                if nxt not in index:
                    index[nxt] = low[nxt] = counter
                    counter += 1
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, iter(edges.get(nxt, ()))))
                    advanced = True
                    break
                if nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
            if advanced:
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                comp = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    comp.append(w)
                    if w == node:
                        break
                out.append(comp)
    return out


def stepping_order(components: Sequence[str], edges: Iterable[tuple[str, str]]) -> list[str]:
    """Default order in which the Gauss-Seidel master steps the components.

    Parameters
    ----------
    components : sequence of str
        Component names in declaration order (order inside a loop, tie-break).
    edges : iterable of (str, str)
        ``(source component, target component)`` for every connection.

    Returns
    -------
    list of str
        Receivers before their sources across feedback loops (reverse topological
        order of the strongly connected components); loop members in declaration
        order; independent parts in declaration order.
    """
    rank = {c: i for i, c in enumerate(components)}
    succ: dict[str, set[str]] = {c: set() for c in components}
    for a, b in edges:
        if a != b:
            succ[a].add(b)
    sccs = strongly_connected(list(components), {c: sorted(s, key=rank.get) for c, s in succ.items()})
    comp_of = {c: i for i, scc in enumerate(sccs) for c in scc}
    n = len(sccs)
    # reversed condensation: an SCC is ready once every SCC it feeds has been placed
    pending = [0] * n
    feeders: list[set[int]] = [set() for _ in range(n)]
    for a, targets in succ.items():
        for b in targets:
            ia, ib = comp_of[a], comp_of[b]
            if ia != ib and ia not in feeders[ib]:
                feeders[ib].add(ia)
                pending[ia] += 1
    first = [min(rank[c] for c in scc) for scc in sccs]
    ready = sorted((i for i in range(n) if pending[i] == 0), key=lambda i: first[i])
    order: list[str] = []
    while ready:
        i = ready.pop(0)
        order.extend(sorted(sccs[i], key=rank.get))
        for j in feeders[i]:
            pending[j] -= 1
            if pending[j] == 0:
                ready.append(j)
        ready.sort(key=lambda k: first[k])
    return order


def _component(variable: str) -> str:
    return variable.partition(".")[0]


def direct_inputs(connections: Iterable[tuple[str, str]], feedthrough: Mapping[str, Iterable[str]],
                  solved: Iterable[str] = ()) -> dict[str, list[str]]:
    """``"comp.output" -> ["comp.input", ...]``: the *connected* inputs each output depends on directly.

    Parameters
    ----------
    connections : iterable of (str, str)
        ``("comp.output", "comp.input")`` pairs.
    feedthrough : mapping of str -> iterable of str
        For each ``"comp.input"``, the outputs of the same FMU that depend on it directly.
    solved : iterable of str
        Variables of algebraic loops the master iterates: their outputs are recomputed from
        the converged inputs at every communication point, so they pass nothing late.
    """
    connected = {inp for _, inp in connections}
    solved = set(solved)
    out: dict[str, list[str]] = {}
    for inp, outputs in feedthrough.items():
        if inp not in connected:
            continue  # a start value: constant over the run
        for o in outputs:
            if o not in solved:
                out.setdefault(o, []).append(inp)
    return out


def dependency_order(components: Sequence[str], connections: Iterable[tuple[str, str]],
                     feedthrough: Mapping[str, Iterable[str]], solved: Iterable[str] = ()) -> list[str]:
    """Default Gauss-Seidel order that follows the declared direct dependencies (module docstring).

    Parameters
    ----------
    components : sequence of str
        Component names in declaration order.
    connections : iterable of (str, str)
        ``("comp.output", "comp.input")`` pairs.
    feedthrough : mapping of str -> iterable of str
        For each ``"comp.input"``, the outputs of the same FMU that depend on it directly.
    solved : iterable of str
        Variables of the algebraic loops the master iterates (see :func:`direct_inputs`).

    Returns
    -------
    list of str
        :func:`stepping_order` of the graph in which every connection from a direct output
        runs from the sources of the inputs it depends on, with each pass-through component
        moved to just before the first consumer of its direct outputs.
    """
    connections = list(connections)
    producer = {inp: out for out, inp in connections}
    direct = direct_inputs(connections, feedthrough, solved)

    def origins(output: str, seen: frozenset) -> set[str]:
        """Components whose non-direct outputs reach ``output`` within one step (through pass-throughs)."""
        if output not in direct or output in seen:
            return {_component(output)}
        seen = seen | {output}
        return {c for inp in direct[output] for c in origins(producer[inp], seen)}

    edges: list[tuple[str, str]] = []
    passes: dict[str, set[str]] = {}  # pass-through component -> components consuming its direct outputs
    for out, inp in connections:
        source, target = _component(out), _component(inp)
        if out in direct:
            if source != target:
                passes.setdefault(source, set()).add(target)
            edges += [(o, target) for o in sorted(origins(out, frozenset()))]
        else:
            edges.append((source, target))
    order = stepping_order(components, edges)
    if not passes:
        return order
    # consumers first: a chain F1 -> F2 -> C places F2 before C, then F1 before F2
    rank = {c: i for i, c in enumerate(components)}
    groups = strongly_connected(sorted(passes, key=rank.get),
                                {f: sorted((c for c in cs if c in passes), key=rank.get) for f, cs in passes.items()})
    for group in groups:  # Tarjan emits a component after every component it reaches
        for f in sorted(group, key=order.index):
            order.remove(f)
            order.insert(min(order.index(c) for c in passes[f]), f)
    return order


def initialization_order(components: Sequence[str], edges: Iterable[tuple[str, str]]) -> list[str]:
    """Order of the initialisation sweeps: sources before receivers (topological), loops in declaration order.

    Parameters
    ----------
    components : sequence of str
        Component names (declaration order is the tie-break).
    edges : iterable of (str, str)
        ``(source, target)`` of every connection and initial binding.
    """
    edges = list(edges)
    reverse = stepping_order(list(components), [(b, a) for a, b in edges])
    return reverse


def _variable_edges(connections: Iterable[tuple[str, str]],
                    feedthrough: Mapping[str, Iterable[str]]) -> dict[str, list[str]]:
    """The variable graph: output -> connected input, input -> the outputs that depend on it directly."""
    edges: dict[str, list[str]] = {}
    for out, inp in connections:
        edges.setdefault(out, []).append(inp)
    for inp, outs in feedthrough.items():
        edges.setdefault(inp, []).extend(outs)
    return edges


def _cyclic_parts(edges: Mapping[str, list[str]]) -> list[list[str]]:
    """The strongly connected parts of a graph that hold a cycle (more than one node, or a self-loop)."""
    nodes = sorted(set(edges) | {v for vs in edges.values() for v in vs})
    return [scc for scc in strongly_connected(nodes, edges) if len(scc) > 1 or scc[0] in edges.get(scc[0], ())]


def find_algebraic_loop(
    connections: Iterable[tuple[str, str]],
    feedthrough: Mapping[str, Iterable[str]],
) -> list[str] | None:
    """A cycle of direct-feedthrough dependencies, or None.

    Parameters
    ----------
    connections : iterable of (str, str)
        ``("comp.output", "comp.input")`` pairs.
    feedthrough : mapping of str -> iterable of str
        For each ``"comp.input"``, the ``"comp.output"`` variables of the same FMU
        that depend on it directly.

    Returns
    -------
    list of str or None
        The variables on one cycle, first repeated at the end
        (``["a.y", "b.u", "b.y", "a.u", "a.y"]``), or None if there is none.
    """
    edges = _variable_edges(connections, feedthrough)
    for scc in _cyclic_parts(edges):
        members = set(scc)
        # walk inside the SCC until a node repeats: that is a cycle
        start = min(scc)
        path = [start]
        seen = {start: 0}
        node = start
        while True:
            node = next(v for v in edges[node] if v in members)
            if node in seen:
                cycle = path[seen[node]:] + [node]
                return cycle
            seen[node] = len(path)
            path.append(node)
    return None


def algebraic_loop_groups(
    connections: Iterable[tuple[str, str]],
    feedthrough: Mapping[str, Iterable[str]],
) -> list[list[str]]:
    """The variables of each set of intertwined algebraic loops (a strongly connected part of the variable graph).

    Parameters
    ----------
    connections, feedthrough
        As for :func:`find_algebraic_loop`.

    Returns
    -------
    list of list of str
        One sorted list of ``"comp.var"`` names per group (empty: no algebraic loop).
    """
    return [sorted(scc) for scc in _cyclic_parts(_variable_edges(connections, feedthrough))]
