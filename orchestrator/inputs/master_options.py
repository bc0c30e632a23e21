"""The master's options a scenario (or a command line) chooses from (:mod:`orchestrator.cosim.master`)."""

#: fixed-step master algorithms
ALGORITHMS = ("gauss-seidel", "jacobi")
#: how coupled inputs are formed from the sources' samples
EXTRAPOLATIONS = ("hold", "linear")
