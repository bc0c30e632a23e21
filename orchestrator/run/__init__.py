"""One scenario run, from the checked system to its files.

Modules
-------
runner          co-simulation, results, analyses, plots, optional reference: one output folder
results         ``timeseries.csv`` and ``summary.json`` of a run
analyses        contact loss, fatigue loads and spectra of a run
comparison      the monolithic reference of a scenario and the side-by-side report
derived         drivetrain quantities derived from a run (generator vs ideal gearbox, Fig. 16)
plots           rotor speed, generator speed, contact forces (Fig. 15-17)
analysis_plots  spectra, load duration distributions, load-event responses
"""
