"""Outputs of the commands that analyse a drivetrain rather than run a scenario.

Modules
-------
modal               ``dtcosim modes``: mode table, free-response check, Campbell diagram, files
modal_plots         mode shapes and Campbell diagram as PNG
reference_cases     ``dtcosim reference``: time series, summary and plot of a reference case
"""
