"""Thin pythonfmu slaves over the physics in components/, and the FMU build (see build_fmus.py)."""
