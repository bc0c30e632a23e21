#!/usr/bin/env python3
"""FMU builds into an empty folder on one process against two (``fmus.build_pool``), taking turns.

What a first ``dtcosim run`` pays before it can step (issue 34.3): it builds the three FMUs of the
paper's scenario, a ``dtcosim build`` the five preset FMUs. Each build runs in a fresh Python
process (``fmus.build.build_all`` after importing the command line, as a run has imported it) with
an empty per-user cache apart from the compiled FMU binary, so every build pays what a first one
pays in its process (the source closures, the bytecode, fmpy's imports) but not the binary's
one-time compile; the kernels are interpreted as on a first run (``DTCOSIM_AOT=0 DTCOSIM_JIT=0``).
Printed: the medians of the wall time (what the user waits for) and of the CPU time of the process
and its children (the work, which a second process does not reduce), and their ratios.

Run: ``python benchmarks/bench_builds.py [--repeat 5] [--fmu NAME ...]`` (default: the paper scenario's three).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
DEFAULT_FMUS = ("Gearbox", "GeneratorRotor", "WindSource")
CHILD = """
import sys
import orchestrator.commands.cli  # what a run has imported when it builds
from fmus.build import build_all
build_all(sys.argv[1], names=sys.argv[2].split(","))
"""


def timed_build(names: list[str], processes: int, cache: Path, out: Path) -> tuple[float, float]:
    """(wall, CPU) seconds of one build in a fresh process; CPU is the process's and its forked builder's."""
    env = {**os.environ, "DTCOSIM_CACHE_DIR": str(cache), "DTCOSIM_BUILD_WORKERS": str(processes),
           "DTCOSIM_AOT": "0", "DTCOSIM_JIT": "0"}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-c", CHILD, str(out), ",".join(names)], cwd=REPO, env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"the build failed:\n{proc.stderr.read().decode(errors='replace')}")
    return wall, usage.ru_utime + usage.ru_stime


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--fmu", nargs="+", default=list(DEFAULT_FMUS))
    args = parser.parse_args()
    times: dict[int, list[tuple[float, float]]] = {1: [], 2: []}
    with tempfile.TemporaryDirectory(prefix="dtcosim-bench-builds-") as tmp:
        cache = Path(tmp) / "cache"
        timed_build(args.fmu[:1], 1, cache, Path(tmp) / "warm-up")  # compiles the FMU binary once
        for i in range(args.repeat):
            for processes in (1, 2):
                out = Path(tmp) / f"out-{processes}-{i}"
                times[processes].append(timed_build(args.fmu, processes, cache, out))
                shutil.rmtree(out)
    print(f"building {', '.join(args.fmu)} into an empty folder, medians of {args.repeat} taking turns")
    medians = {}
    for processes, values in times.items():
        wall = statistics.median(w for w, _ in values)
        cpu = statistics.median(c for _, c in values)
        medians[processes] = (wall, cpu)
        runs = ", ".join(f"{w:.2f}" for w, _ in values)
        print(f"  {processes} process{'es' if processes > 1 else '  '}  {wall:6.2f} s wall  {cpu:6.2f} s CPU   "
              f"(walls {runs})")
    ratios = [one[0] / two[0] for one, two in zip(times[1], times[2])]
    print(f"ratio of wall times, 1 / 2 processes: {medians[1][0] / medians[2][0]:.2f} "
          f"(median of the turns' ratios {statistics.median(ratios):.2f}); "
          f"CPU 2 / 1: {medians[2][1] / medians[1][1]:.2f}")


if __name__ == "__main__":
    main()
