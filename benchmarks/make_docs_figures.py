"""The images of docs/ and the sensitivity-study tables of docs/studies.md, made from scratch.

Runs the packaged study ``paper-sensitivity`` (Sec. 4.1, 7 x 7 points on the monolithic
engine; what ``dtcosim sweep paper-sensitivity`` runs) into a temporary folder (or ``--work``),
copies its heat maps into ``--out`` under the names docs/ uses (:data:`FIGURES`), and prints the
tables docs/studies.md quotes: I_max,acc over R1 x lambda, and CPU time, LSODA steps and
right-hand-side calls per lambda (means over R1). The other figures are each made by a benchmark script
of this folder (:data:`SCRIPTS`, e.g. ``load_sharing.png`` by ``load_sharing.py``). I_max,acc, steps and calls are deterministic;
CPU times move with the load of the machine.

Nothing is written into the source tree unless ``--out`` names it::

    python benchmarks/make_docs_figures.py --out docs/img [--workers 2] [--work DIR]
"""

from __future__ import annotations

import argparse
import csv
import shutil
import statistics
import subprocess
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

from orchestrator.inputs.study import find_study, load_study
from orchestrator.study.prepare import prepare_study
from orchestrator.study.sweep import run_sweep

#: docs/img name -> the file the study writes
FIGURES = {
    "study-fig12-I_max_acc.png": "fig12_I_max_acc.png",
    "study-fig13-cpu_time.png": "fig13_cpu_time.png",
}
#: docs/img name -> the benchmark script (beside this one) that makes it with ``--out``
SCRIPTS = {
    "load_sharing.png": "load_sharing.py",
}


def _column(header: list[str], prefix: str) -> int:
    """Index of the column whose header starts with ``prefix`` (headers carry units: ``I_max_acc [rad/s^2]``)."""
    for i, name in enumerate(header):
        if name == prefix or name.startswith(prefix + " "):
            return i
    raise KeyError(f"no column {prefix!r} in {header}")


def print_tables(table: Path) -> None:
    """The Markdown tables of docs/studies.md from the study's ``results.csv``."""
    with open(table, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    header, data = rows[0], rows[1:]
    r1, lam = _column(header, "gearbox.R1"), _column(header, "gearbox.stage1.lambda")
    acc, cpu = _column(header, "I_max_acc"), _column(header, "cpu_time")
    steps, rhs = _column(header, "steps"), _column(header, "rhs_calls")
    r1_values = sorted({float(r[r1]) for r in data})
    lam_values = sorted({float(r[lam]) for r in data})
    grid = {(float(r[lam]), float(r[r1])): r for r in data}
    print("I_max,acc [1e5 rad/s^2] (rows lambda [1/mm], columns R1):\n")
    print("| lambda \\ R1 | " + " | ".join(f"{v:.3g}" for v in r1_values) + " |")
    print("| --- " * (len(r1_values) + 1) + "|")
    for lv in lam_values:
        cells = [f"{float(grid[lv, rv][acc]) / 1e5:.2f}" for rv in r1_values]
        print(f"| {lv * 1e-3:.0f} | " + " | ".join(cells) + " |")
    per = defaultdict(list)
    for r in data:
        per[float(r[lam])].append(r)
    print("\nCPU time [s], LSODA steps and RHS calls, mean over R1 per lambda [1/mm]:\n")
    print("| lambda [1/mm] | " + " | ".join(f"{lv * 1e-3:.0f}" for lv in lam_values) + " |")
    print("| --- " * (len(lam_values) + 1) + "|")
    for label, col, fmt in (("CPU time [s]", cpu, "{:.3f}"), ("LSODA steps", steps, "{:.0f}"),
                            ("RHS calls", rhs, "{:.0f}")):
        cells = [fmt.format(statistics.fmean(float(r[col]) for r in per[lv])) for lv in lam_values]
        print(f"| {label} | " + " | ".join(cells) + " |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True, help="folder for the images (docs/img to update the docs)")
    parser.add_argument("--workers", type=int, default=2, help="Dask workers of the study (default 2)")
    parser.add_argument("--work", type=Path, default=None,
                        help="keep the study's results here (default: a temporary folder)")
    args = parser.parse_args()
    prepared = prepare_study(load_study(find_study("paper-sensitivity")))
    with tempfile.TemporaryDirectory(prefix="dtcosim-docs-figures-") as tmp:
        work = args.work or Path(tmp) / "paper-sensitivity"
        report = run_sweep(prepared, work, workers=args.workers)
        if report.failed:
            raise SystemExit(f"make_docs_figures: {report.failed} point(s) of paper-sensitivity failed; see {work}")
        args.out.mkdir(parents=True, exist_ok=True)
        for name, made in FIGURES.items():
            shutil.copyfile(work / made, args.out / name)
            print(f"{args.out / name}  (from {made} of dtcosim sweep paper-sensitivity)")
        print()
        print_tables(work / "results.csv")
    for name, script in SCRIPTS.items():
        subprocess.run([sys.executable, str(Path(__file__).with_name(script)), "--out", str(args.out / name)], check=True)
        print(f"{args.out / name}  (from benchmarks/{script})")


if __name__ == "__main__":
    main()
