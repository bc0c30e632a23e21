"""Which file a run's samples go to: ``timeseries.csv`` or ``timeseries.parquet``.

Chosen by the scenario's ``[record] format`` or ``dtcosim run --results``:

``csv``
    Text, one line per sample (``timeseries.csv``): readable by anything, about
    20 bytes per value.
``parquet``
    Binary columnar (``timeseries.parquet``): 8 bytes per value, units and FMI
    types as metadata; ``pandas.read_parquet``, MATLAB ``parquetread``.
``auto`` (default)
    Parquet for long runs, more than :data:`AUTO_PARQUET_VALUES` values (samples x
    recorded variables: a 600 s paper run at 5 ms has 2.6 million), CSV otherwise
    (a 60 s paper run, 0.26 million at 5 ms, 1.3 million at 1 ms).

A light module: the command line takes its choices from here.
"""

from __future__ import annotations

#: the values of ``[record] format`` and ``--results``
RESULTS_FORMATS = ("auto", "csv", "parquet")
#: ``auto`` writes Parquet above this many values (samples x recorded variables; about 40 MB as CSV)
AUTO_PARQUET_VALUES = 2_000_000
#: file name of each concrete format
RESULTS_FILES = {"csv": "timeseries.csv", "parquet": "timeseries.parquet"}


def concrete_format(requested: str, samples: int, variables: int) -> str:
    """``csv`` or ``parquet`` for a run of ``samples`` rows of ``variables`` recorded variables."""
    if requested not in RESULTS_FORMATS:
        raise ValueError(f"results format {requested!r}: expected one of {', '.join(RESULTS_FORMATS)}")
    if requested != "auto":
        return requested
    return "parquet" if samples * max(variables, 1) > AUTO_PARQUET_VALUES else "csv"
