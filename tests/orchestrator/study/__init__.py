"""Tests of studies and sweeps (a package, so its conftest does not shadow the other test folders' ``conftest``)."""
