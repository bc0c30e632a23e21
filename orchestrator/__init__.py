"""dtcosim orchestrator: scenarios, master algorithms, results, plots, studies and the CLI.

The master talks to the FMUs only through FMI (fmpy). It imports
:mod:`components` only for the monolithic reference and for analyses.

Co-simulation modules
---------------------
scenario        system description (frozen dataclasses) and its TOML format
fmu_interface   what an FMU offers, read from modelDescription.xml
system          a scenario checked against its FMUs (ResolvedSystem)
graph           stepping/initialisation order, algebraic-loop detection
fmi_runtime     FMU instances through fmpy's FMU2Slave, log capture
master          fixed-step Gauss-Seidel/Jacobi master (generated stepping loop)
results         timeseries.csv and summary.json
derived         component roles, ideal gearbox ratio, Fig. 16 check
plots           Fig. 15-17 as PNG
compare         monolithic reference of a scenario and the comparison report
ssp             SSP 1.0 export and import
libcosim_host   running an SSP in libcosim (child process with libpython preloaded)
fmu_store       locating/building the project's FMUs
runner          one run from scenario to files (used by ``dtcosim run``)

Study modules (``dtcosim sweep``, docs/studies.md)
-------------------------------------------------
study           the study file: axes, explicit points, seeds, measures, plots (StudyError)
measures        built-in measures (eq. 11-12, times, solver work) and summary statistics
study_models    built-in monolithic models (the Sec. 4.1 variant)
study_engine    one point in a Dask worker: monolithic and co-simulation engines, FMUs from bytes
study_prepare   checking a study against its base, the workers' payload, point keys
sweep           the Dask loop: LocalCluster or existing cluster, re-runs, Ctrl-C
journal         the append-only results journal (one JSON line per finished point)
study_report    results.csv and study.json regenerated from the journal
study_plots     heat maps (Fig. 12-13) and line plots of the measures
"""
