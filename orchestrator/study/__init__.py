"""Parameter studies on Dask: many runs of one base system with parameters changed.

Modules
-------
prepare         a study checked against its base; point keys; the payload workers get
engine          one point on a worker (co-simulation or monolithic)
measure_values  the numbers behind the measures (statistics, DELs, rates)
models          built-in monolithic models (the paper's Sec. 4.1 variant)
sweep           the Dask loop: submit, collect, journal
journal         the append-only journal that makes sweeps resumable
report          results.csv, study.json and plots from the journal
plots           heat maps and line plots of measures over the grid
"""
