"""dtcosim orchestrator: scenarios, master algorithms, results, plots, studies and the CLI.

The master talks to the FMUs only through FMI (fmpy). It imports
:mod:`components` only for the monolithic reference and for analyses.
"""
