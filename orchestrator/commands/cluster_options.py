"""The options every command that runs points on a cluster shares: ``--workers``, ``--scheduler``, ``--dashboard``,
``--executor``.

Used by ``dtcosim sweep`` and ``dtcosim loads``: one definition of what a
LocalCluster exposes (:mod:`orchestrator.study.cluster`: TLS with temporary
credentials, no dashboard unless asked) and of the checks on an existing cluster.
"""

from __future__ import annotations

import argparse
import os
import sys


def add_cluster_arguments(p: argparse.ArgumentParser) -> None:
    """Add ``--workers``, ``--scheduler``, ``--dashboard`` and ``--executor`` to a subcommand's parser."""
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="workers of the LocalCluster: processes with one thread each (default: CPU count; at "
                        f"most {WORKERS_PER_CPU} x the CPU count)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="use an existing Dask cluster through its scheduler, e.g. tls://10.0.0.5:8786 (left running; "
                        "TLS settings from the Dask configuration, see docs/studies.md)")
    p.add_argument("--dashboard", nargs="?", const="127.0.0.1:8787", default=None, metavar="HOST:PORT",
                   help="start the LocalCluster's Dask dashboard (default address 127.0.0.1:8787; without this "
                        "option nothing listens on it)")
    from ..study.sweep import EXECUTORS, MIN_CLUSTER_WORK_S

    p.add_argument("--executor", choices=EXECUTORS, default="auto",
                   help="where the points run without --scheduler: auto (default) runs them in this process while "
                        f"the pending ones add up to less than {MIN_CLUSTER_WORK_S:g} s of work, measured on the "
                        "first, and hands the rest to a LocalCluster once they do not (a small study starts no "
                        "cluster); process: all in this process, one at a time; dask: all on a LocalCluster")


def where(args: argparse.Namespace) -> str:
    """Where the points will run, for the command's first line."""
    if args.scheduler:
        return f"scheduler {args.scheduler}"
    cluster = f"a LocalCluster of {args.workers or os.cpu_count()} workers"
    return {"process": "this process", "dask": cluster}.get(args.executor, f"this process while small, else {cluster}")


def ran(report) -> str:
    """``on 2 workers``, ``in this process``, or both: where a sweep's points ran (its :class:`SweepReport`)."""
    here = report.in_process
    there = report.submitted - here
    if here and there:
        return f"{here} in this process, {there} on {report.workers} workers"
    return "in this process" if here else f"on {report.workers} workers"

#: workers per CPU a LocalCluster may have: each is a process of its own (its interpreter, numpy and the
#: FMUs it loads, 150-300 MB); beyond the cores they only take turns
WORKERS_PER_CPU = 4


def max_workers() -> int:
    """The most ``--workers`` of a LocalCluster on this machine: :data:`WORKERS_PER_CPU` x its CPUs (at least 4)."""
    return max(4, WORKERS_PER_CPU * (os.cpu_count() or 1))


def check_workers(args: argparse.Namespace, error: type) -> None:
    """Refuse ``--workers`` outside ``1..max_workers()`` (before anything is read or started), as ``error``."""
    if args.workers is None:
        return
    limit = max_workers()
    if not 1 <= args.workers <= limit:
        raise error("--workers", args.workers, f"an integer from 1 to {limit} ({WORKERS_PER_CPU} x the "
                    f"{os.cpu_count() or 1} CPUs of this machine: each worker is a process of 150-300 MB, and more "
                    "than the cores only take turns; for more, start a cluster and give --scheduler)")


def check_cluster_arguments(args: argparse.Namespace, command: str) -> None:
    """Warn about an unauthenticated ``--scheduler``; refuse ``--dashboard`` with it (before anything runs).

    Raises
    ------
    StudyError
        ``--dashboard`` together with ``--scheduler``.
    """
    from ..inputs.study import StudyError

    if args.scheduler:
        from ..study.cluster import is_authenticated

        if not is_authenticated(args.scheduler):
            print(f"dtcosim {command}: warning: {args.scheduler} is not authenticated: any process that reaches it "
                  "can run code on its workers (use a TLS cluster, see docs/studies.md)", file=sys.stderr)
    if args.dashboard and args.scheduler:
        raise StudyError("--dashboard", args.dashboard, "no dashboard option with --scheduler (the existing "
                         "cluster has its own)")
    if args.scheduler and args.executor != "auto":
        raise StudyError("--executor", args.executor, "no --executor with --scheduler (the points run on that "
                         "cluster)")
