"""Imported first by the CPU-time benchmarks: one BLAS / OpenMP thread per process (unless set).

OpenBLAS's worker threads busy-wait for a while (about 0.1 s) after a multi-threaded call
before they sleep, and process CPU time counts every thread. In bench_cosim the monolithic
reference's output evaluation (products over the whole 12 000-sample grid) started them:
run after the co-simulations, the reference measured 0.26-0.31 s CPU of which ~0.12 s was
that spinning (0.14 s with one thread); taking turns with the co-simulation, the spinning
was charged to the co-simulation run that followed (CPU 0.36 s against 0.25 s wall). The
arrays of a step are tiny: one thread does the same work without the spinning, and the
ratios then compare work with work. Must be imported before numpy.
"""

import os

for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")
