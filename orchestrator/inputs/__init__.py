"""The user's input files, checked before anything runs.

Modules
-------
files               reading TOML, the packaged files, finding a file by path or packaged name
scenario            a co-simulation scenario and its TOML format
study               a parameter study and its TOML format
load_events         generator load events of a scenario (``[[events]]``)
analysis_settings   settings of the result analyses (``[analysis]``)
measures            what a study measures per run (names, units, parsing)
"""
