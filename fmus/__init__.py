"""Thin pythonfmu slaves over the physics in components/ (``fmus.slaves``), and the FMU build (``fmus.build``, build_fmus.py)."""
