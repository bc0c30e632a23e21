"""Cases of :func:`fmus.build_pool.build_each`, each run in a fresh Python (``python -m tests.helpers.build_pool_cases
CASE FOLDER``) whose only thread is its main one (a pytest process may hold threads another test started, and
the pool does not fork beside a thread). Each prints one JSON line: what happened."""

from __future__ import annotations

import json
import os
import signal
import sys
import time
from pathlib import Path

from fmus.build_pool import BuildPoolError, build_each

PARENT = os.getpid()


def _in_child() -> bool:
    return os.getpid() != PARENT


def _pid_after(seconds: float):
    def build(name: str) -> tuple[str, int]:
        time.sleep(seconds)  # long enough that both processes take names
        return name, os.getpid()
    return build


class _Local(Exception):  # noqa: N818 - a class the pickle of the child's result cannot name
    def __reduce__(self):
        raise TypeError("not picklable")


def both_processes(folder: Path) -> dict:
    results = build_each(_pid_after(0.2), ["a", "b", "c", "d"], processes=2)
    return {"names": [n for n, _ in results], "pids": sorted({p for _, p in results}), "parent": PARENT}


def one_process(folder: Path) -> dict:
    results = build_each(_pid_after(0.05), ["a", "b", "c"])  # DTCOSIM_BUILD_WORKERS=1 in the environment
    return {"names": [n for n, _ in results], "pids": sorted({p for _, p in results}), "parent": PARENT}


def beside_a_thread(folder: Path) -> dict:
    import threading

    stop = threading.Event()
    worker = threading.Thread(target=stop.wait)
    worker.start()
    try:
        results = build_each(_pid_after(0.05), ["a", "b", "c"], processes=2)
    finally:
        stop.set()
        worker.join()
    return {"pids": sorted({p for _, p in results}), "parent": PARENT}


def first_failure_in_order(folder: Path) -> dict:
    def build(name: str) -> str:
        time.sleep(0.1)
        if name in ("b", "d"):
            raise ValueError(f"cannot build {name} (in pid {os.getpid()})")
        return name

    try:
        build_each(build, ["a", "b", "c", "d"], processes=2)
    except ValueError as exc:
        return {"raised": "ValueError", "message": str(exc)}
    return {"raised": None}


def unpicklable_failure_in_child(folder: Path) -> dict:
    def build(name: str) -> str:
        time.sleep(0.1)
        if _in_child():
            raise _Local(f"{name} failed in the child")
        return name

    try:
        build_each(build, ["a", "b"], processes=2)
    except BuildPoolError as exc:
        return {"raised": "BuildPoolError", "message": str(exc)}
    return {"raised": None}


def child_killed(folder: Path) -> dict:
    built_here = []

    def build(name: str) -> str:
        if _in_child():
            os.kill(os.getpid(), signal.SIGKILL)
        time.sleep(0.3)
        built_here.append(name)
        return name

    try:
        build_each(build, ["a", "b", "c"], processes=2)
    except BuildPoolError as exc:
        return {"raised": "BuildPoolError", "message": str(exc), "built_here": built_here}
    return {"raised": None}


def interrupted(folder: Path) -> dict:
    """The parent is interrupted while the child builds: the child gets SIGINT, cleans up and is waited for."""
    started, cleaned = folder / "child-started", folder / "child-cleaned-up"

    def build(name: str) -> str:
        if _in_child():
            started.touch()
            try:
                time.sleep(30)
            finally:  # what an interrupted build does: its temporary folder removed
                cleaned.touch()
            return name
        while not started.exists():
            time.sleep(0.01)
        raise KeyboardInterrupt

    t0 = time.monotonic()
    try:
        build_each(build, ["a", "b"], processes=2)
    except KeyboardInterrupt:
        pass
    try:
        os.waitpid(-1, os.WNOHANG)
        unreaped = True
    except ChildProcessError:
        unreaped = False
    return {"cleaned": cleaned.exists(), "seconds": time.monotonic() - t0, "unreaped_child": unreaped}


def binary_compiled_once(folder: Path) -> dict:
    """Both processes ask for the FMU binary at once (DTCOSIM_CACHE_DIR empty): one compiles, the other waits."""
    from fmus import binary

    compile_ = binary._compile
    log = folder / "compiles.log"

    def logged(cc, target):
        with open(log, "a") as out:
            out.write(f"{os.getpid()}\n")
        return compile_(cc, target)

    binary._compile = logged
    paths = build_each(lambda name: str(binary.compiled_binary()), ["a", "b"], processes=2)
    return {"paths": paths, "compiles": log.read_text().split()}


def fmus_on_two_processes(folder: Path) -> dict:
    """Real FMUs built on two processes, each unpacked for the run by the process that built it."""
    from fmus import build, build_pool
    from orchestrator.cosim.fmu_interface import file_sha256
    from orchestrator.cosim.unpacked_fmus import is_unpacked
    from orchestrator.provision.unpack_ahead import unpack_ahead

    runs = []
    run = build_pool._Pool.run

    def recorded(self):
        runs.append(len(self.names))
        return run(self)

    def unpack(path: Path):
        folder = unpack_ahead(path)
        print(json.dumps({"unpacked": [path.stem, os.getpid(), str(folder)]}), flush=True)  # the child's too
        return folder

    build_pool._Pool.run = recorded
    built = build.build_all(folder, names=sys.argv[3].split(","), after_each=unpack)
    return {"pool_runs": runs, "built": [[b.name, str(b.path), b.build_id] for b in built],
            "unpacked_now": [is_unpacked(file_sha256(b.path)) for b in built], "parent": PARENT}


if __name__ == "__main__":
    print(json.dumps(globals()[sys.argv[1]](Path(sys.argv[2]))), flush=True)
