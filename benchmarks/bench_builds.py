#!/usr/bin/env python3
"""FMU builds into an empty folder on one process against two (``fmus.build_pool``), taking turns.

What a first ``dtcosim run`` pays before it can step (issue 34.3): it builds the three FMUs of the
paper's scenario, a ``dtcosim build`` the five preset FMUs. Each build runs in a fresh Python
process (``fmus.build.build_all`` after importing the command line, as a run has imported it) with
an empty per-user cache apart from the compiled FMU binary, so every build pays what a first one
pays in its process (the source closures, the bytecode, fmpy's imports) but not the binary's
one-time compile; the kernels are interpreted as on a first run (``DTCOSIM_AOT=0 DTCOSIM_JIT=0``).
Printed: the medians of the wall time (what the user waits for) and of the CPU time of the process
and its children (the work, which a second process does not reduce), and their ratios. With
``--baseline REV`` the sources of git revision ``REV`` (``git archive`` into a temporary folder: the
repository is not touched) build the same FMUs in the same turns, and the ratios of this tree's
times to theirs are printed (medians of the turns' ratios), also of the builds' own CPU: each build
process's less that of a process that only imports what it does (``imports only``, in the same turn),
and the sizes of the FMU archives.

Run: ``python benchmarks/bench_builds.py [--repeat 5] [--fmu NAME ...] [--baseline REV]`` (default: the paper
scenario's three, no baseline).
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

from baseline_tree import archive_tree

REPO = Path(__file__).resolve().parents[1]
DEFAULT_FMUS = ("Gearbox", "GeneratorRotor", "WindSource")
CHILD = """
import sys
import orchestrator.commands.cli  # what a run has imported when it builds
from fmus.build import build_all
build_all(sys.argv[1], names=[name for name in sys.argv[2].split(",") if name])
"""


def timed_build(names: list[str], processes: int, cache: Path, out: Path, tree: Path = REPO) -> tuple[float, float]:
    """(wall, CPU) seconds of one build in a fresh process importing dtcosim from ``tree``; CPU is the process's and
    its forked builder's."""
    env = {**os.environ, "DTCOSIM_CACHE_DIR": str(cache), "DTCOSIM_BUILD_WORKERS": str(processes),
           "DTCOSIM_AOT": "0", "DTCOSIM_JIT": "0"}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    t0 = time.perf_counter()
    env.pop("PYTHONPATH", None)
    code = "import sys; sys.path.insert(0, sys.argv.pop(1))\n" + CHILD
    proc = subprocess.Popen([sys.executable, "-c", code, str(tree), str(out), ",".join(names)], cwd=tree, env=env,
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
    parser.add_argument("--baseline", metavar="REV", help="also build with the sources of git revision REV")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="dtcosim-bench-builds-") as tmp:
        trees = {"this tree": REPO}
        if args.baseline:
            trees[args.baseline] = archive_tree(args.baseline, Path(tmp))
        times = {(label, processes): [] for label in trees for processes in (0, 1, 2)}  # 0: imports only
        sizes: dict[str, dict[str, int]] = {}
        cache = Path(tmp) / "cache"
        for tree in trees.values():  # compiles the FMU binary once (twice if the baseline's C sources differ)
            timed_build(args.fmu[:1], 1, cache, Path(tmp) / "warm-up", tree)
            shutil.rmtree(Path(tmp) / "warm-up")
        for i in range(args.repeat):
            for label, processes in times:
                out = Path(tmp) / f"out-{i}"
                names = args.fmu if processes else []
                times[label, processes].append(timed_build(names, max(processes, 1), cache, out, trees[label]))
                if processes == 1:
                    sizes[label] = {path.stem: path.stat().st_size for path in sorted(out.glob("*.fmu"))}
                shutil.rmtree(out, ignore_errors=True)
    print(f"building {', '.join(args.fmu)} into an empty folder, medians of {args.repeat} taking turns")
    medians = {}
    for (label, processes), values in times.items():
        wall = statistics.median(w for w, _ in values)
        cpu = statistics.median(c for _, c in values)
        medians[label, processes] = (wall, cpu)
        runs = ", ".join(f"{w:.2f}" for w, _ in values)
        what = f"{processes} process{'es' if processes > 1 else '  '}" if processes else "imports only"
        print(f"  {label:>10}  {what}  {wall:6.2f} s wall  {cpu:6.2f} s CPU   (walls {runs})")
    for label in trees:
        ratios = [one[0] / two[0] for one, two in zip(times[label, 1], times[label, 2])]
        print(f"{label}: ratio of wall times, 1 / 2 processes: {medians[label, 1][0] / medians[label, 2][0]:.2f} "
              f"(median of the turns' ratios {statistics.median(ratios):.2f}); "
              f"CPU 2 / 1: {medians[label, 2][1] / medians[label, 1][1]:.2f}")
    if args.baseline:
        for processes in (1, 2):
            pairs = list(zip(times["this tree", processes], times[args.baseline, processes]))
            cpu = statistics.median(now[1] / base[1] for now, base in pairs)
            wall = statistics.median(now[0] / base[0] for now, base in pairs)
            # the builds' own CPU: each turn's process less the same turn's process that only imported
            own = {label: [t[1] - i[1] for t, i in zip(times[label, processes], times[label, 0])] for label in trees}
            builds = statistics.median(now / base for now, base in zip(own["this tree"], own[args.baseline]))
            print(f"this tree / {args.baseline}, {processes} process{'es' if processes > 1 else ''}: "
                  f"CPU {cpu:.2f}, wall {wall:.2f}; the builds' own CPU {statistics.median(own['this tree']):.2f} "
                  f"against {statistics.median(own[args.baseline]):.2f} s, {builds:.2f} (medians of the turns)")
        print(f"archive sizes, this tree / {args.baseline}: " + ", ".join(
            f"{name} {size / sizes[args.baseline][name]:.3f} ({size} bytes)" for name, size in sizes["this tree"].items()))


if __name__ == "__main__":
    main()
