"""dtcosim orchestrator: input files, the FMI master, runs, studies and the ``dtcosim`` command.

Imports go one way, from the commands down to the base modules:

``commands`` -> ``study`` -> ``run`` -> ``interop`` -> ``cosim`` -> ``inputs`` -> base
(``run`` -> ``raster`` -> base: the run figures' renderer)
(``reports`` sits beside ``run`` and is used only by commands).

Base modules
------------
errors          every user-facing error class (names file, key, value, expectation)
frozen_map      immutable, picklable mappings for the frozen input objects
import_safe_signals  signal handlers that never interrupt an import
figure_files    what every figure file shares: 110 dpi, fixed margins, the palette PNG writer
plotting        matplotlib figures, envelope and backlash-shading helpers shared by the plots
result_files    CSV series, JSON summaries, the versions a result depends on

Subpackages
-----------
inputs      the user's files: scenario and study schemas, load events, analysis settings, measures
cosim       FMU interfaces and store, the checked system, graph, FMI runtime, the master
interop     SSP 1.0 import/export, running a system in libcosim
run         one scenario run: runner, results, analyses, comparison with the reference, plots
raster      the run figures' own renderer on Pillow (no matplotlib): axes, ticks, text, legends
study       parameter studies on Dask: preparation, engine, sweep, journal, report, plots
reports     modal analysis and reference-case outputs (``dtcosim modes``, ``dtcosim reference``)
commands    the ``dtcosim`` command line, one module per subcommand
"""
