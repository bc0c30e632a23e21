"""The compile machinery: one kernel source run compiled (numba, ahead of time) or interpreted.

The physics of :mod:`components.model` is written once, as plain Python functions on floats
and arrays in kernel packages (:mod:`components.model.kernel`). This subpackage knows nothing
of that physics; it turns such sources into runnable forms:

import_statements  the import statements of a source, parsed once per content (also for fmus)
sources      :class:`~components.compile.sources.KernelSource`: a kernel's files and digest
jit          the sources compiled by numba once per process (any copy of them shares it)
numba_cache  numba's disk cache keyed by the sources, in the per-user cache
aot          ahead-of-time extension modules (numba.pycc): compiled code without numba
c_compiler   the machine's C compiler (the ahead-of-time build and the FMU binary need one)
choice       which form runs (``$DTCOSIM_KERNEL``: auto, numpy = interpreted, compiled)
user_cache   the per-user cache folder

It imports nothing from the rest of the project but :mod:`components.errors`.
"""
