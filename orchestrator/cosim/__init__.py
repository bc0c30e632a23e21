"""The co-simulation: FMUs read and checked through FMI only, and the fixed-step master.

It only reads FMUs: finding and building them is :mod:`orchestrator.provision`'s.

Modules
-------
fmu_interface   what an FMU's ``modelDescription.xml`` declares (nothing instantiated)
event_slots     load events placed into the FMUs' event slots
system          a scenario checked against its FMUs
resolved        what that check gives and the master runs (:class:`~orchestrator.cosim.resolved.ResolvedSystem`)
graph           stepping and initialisation order, algebraic loops
fmi_runtime     FMU instances driven through fmpy's raw FMI functions
master          Gauss-Seidel / Jacobi master algorithm
initialisation  the initialisation sweeps
stepping        the stepping plan and its two executors (Python, compiled)
rows            where finished rows go (the run's sink)
outcome         what a run produced (:class:`~orchestrator.cosim.outcome.RunOutcome`)
"""
