"""Other tools' formats and hosts.

Modules
-------
ssp         SSP 1.0 import (``.ssp``, ``.ssd``, folders) and export
libcosim    running a system in libcosim (``libcosimpy``) for cross-checks
"""
