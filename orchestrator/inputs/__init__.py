"""The user's input files, checked before anything runs.

Modules
-------
files               reading TOML, the packaged files, finding a file by path or packaged name
scenario            a co-simulation scenario: components, connections, settings
scenario_file       the scenario file (TOML): schema, loader, finding a packaged one
study               a parameter study: its points
study_file          the study file (TOML): schema and loader
load_cases          a set of load cases (wind bins, operating rows, fatigue options)
load_case_file      the load-case file (TOML): schema and loader
load_events         generator load events of a scenario (``[[events]]``)
analysis_settings   settings of the result analyses (``[analysis]``)
measures            what a study measures per run (names, units, parsing)
"""
