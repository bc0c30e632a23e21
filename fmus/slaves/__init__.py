"""FMI slave classes (pythonfmu) of the dtcosim components.

These modules are copied into every FMU (see :mod:`fmus.build`) together with
``components/``. They must therefore import nothing from this project except
``components`` (written as absolute ``from components...`` imports, which the
build rewrites to package-relative imports) and each other (relative imports).
This ``__init__`` deliberately imports nothing, so an FMU carries only the
slave modules it needs.
"""
