"""Provisioning: finding, building and caching the FMUs a scenario needs, between the commands and the co-simulation.

The commands (and studies) ask this package for the FMU files of a scenario; the
co-simulation (:mod:`orchestrator.cosim`) then only reads them. Built FMUs go to the
FMU folder (:func:`~orchestrator.provision.folders.default_fmu_dir`: a per-user cache,
or ``$DTCOSIM_FMU_DIR``, or a folder the user names with ``--fmu-dir``/``--out``),
never into the installed package or a checkout.

Modules
-------
folders         the default FMU folder and its content-keyed subfolders (drivetrain files, load records)
locate          where a scenario's FMUs are (the scenario's folder, then the FMU folder)
staleness       project FMUs built from other code than the installed dtcosim
drivetrain_fmus Gearbox/GeneratorRotor FMUs built from drivetrain files
series_fmus     TimeSeriesSource FMUs built from load records
project_fmus    every FMU a scenario needs: found, or built when missing or stale (:func:`ensure_fmus`)
"""
