"""The master's options a scenario (or a command line) chooses from (:mod:`orchestrator.cosim.master`)."""

#: fixed-step master algorithms
ALGORITHMS = ("gauss-seidel", "jacobi")
#: how coupled inputs are formed from the sources' samples
EXTRAPOLATIONS = ("hold", "linear")
#: what the master does with an algebraic loop (a cycle of direct feedthrough): refuse the scenario, or solve it
#: at every communication point by fixed-point iteration (:mod:`orchestrator.cosim.algebraic_loops`)
ALGEBRAIC_LOOPS = ("refuse", "iterate")
