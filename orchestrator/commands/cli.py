"""Command-line interface ``dtcosim``.

Each subcommand lives in its own module exposing ``register(subparsers)``,
which adds an argparse sub-parser whose ``func`` attribute runs the command
and returns the process exit code. Only the module of the command that runs is
imported; the others are listed by name and help line
(:mod:`orchestrator.commands.catalogue`).
"""

from __future__ import annotations

import argparse
import atexit
import contextlib
import gc
import importlib
import os
import signal
import sys
import warnings
from collections.abc import Callable, Iterator, Sequence

from components.errors import DtcosimError, os_error_text

from ..cosim.stop_requests import STOP_SIGNALS
from ..import_safe_signals import install, restore
from .catalogue import COMMANDS

#: set (to anything) to see the traceback of an unexpected error instead of its one line
DEBUG_VARIABLE = "DTCOSIM_DEBUG"


def _version_text() -> str:
    """``dtcosim X (python ..., numpy ..., fmpy ..., pythonfmu ...)``: what a result depends on."""
    from components import __version__

    from ..result_files import versions

    deps = ", ".join(f"{k} {v}" for k, v in versions().items() if k != "dtcosim")
    return f"dtcosim {__version__} ({deps})"


class _VersionAction(argparse.Action):
    """``--version``: looks the package versions up only when asked."""

    def __call__(self, parser, namespace, values, option_string=None):
        print(_version_text())
        parser.exit()


def command_named(argv: Sequence[str]) -> str | None:
    """The subcommand ``argv`` runs: its first word, unless help is asked for before it (None: no command)."""
    for word in argv:
        if word in ("-h", "--help"):
            return None
        if not word.startswith("-"):
            return word
    return None


def build_parser(argv: Sequence[str] | None = None) -> argparse.ArgumentParser:
    """The ``dtcosim`` argument parser: every subcommand listed, the one ``argv`` names registered by its module.

    Without ``argv`` every command's module registers its sub-parser (all imported).
    """
    parser = argparse.ArgumentParser(
        prog="dtcosim",
        description="Wind-turbine drivetrain torsional vibration as an FMI 2.0 co-simulation.",
    )
    parser.add_argument("--version", action=_VersionAction, nargs=0,
                        help="print the versions of dtcosim and of what its results depend on, and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    wanted = None if argv is None else command_named(argv)
    for command in COMMANDS:
        if argv is None or command.name == wanted:
            importlib.import_module(command.module).register(sub)
        else:  # listed with its help line; its module is not imported
            sub.add_parser(command.name, help=command.help, add_help=False)
    return parser


def _raise_interrupt(signum, frame) -> None:
    from ..errors import RunInterrupted

    raise RunInterrupted(signum, "the command")


@contextlib.contextmanager
def _command_signals() -> Iterator[None]:
    """The command's stop-signal handlers, each kept out of imports, for the ``with`` block.

    SIGINT keeps its handler (Python's KeyboardInterrupt, or the caller's);
    SIGTERM and SIGHUP raise :class:`~orchestrator.errors.RunInterrupted`. A
    signal the process ignores (SIGHUP under ``nohup``) stays ignored. Every
    handler runs only outside imports (:func:`~orchestrator.import_safe_signals.install`),
    so a Ctrl-C during start-up is one line too, not an ImportError.
    """
    handlers = dict.fromkeys(STOP_SIGNALS, _raise_interrupt)
    handlers[signal.SIGINT] = signal.getsignal(signal.SIGINT)
    if not callable(handlers[signal.SIGINT]):  # SIG_DFL or SIG_IGN: no Python handler to keep out of imports
        del handlers[signal.SIGINT]
    previous = install(handlers)
    try:
        yield
    finally:
        restore(previous)


@contextlib.contextmanager
def _warnings_as_lines(prog: Callable[[], str]) -> Iterator[None]:
    """Python warnings that reach the user (a build's, a library's) as ``dtcosim run: warning: ...`` lines, not as
    Python's ``file:line: UserWarning: ...`` with its source line, for the ``with`` block."""
    previous = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        print(f"{prog()}: warning: {message}", file=sys.stderr if file is None else file)

    warnings.showwarning = show
    try:
        yield
    finally:
        warnings.showwarning = previous


def _prog(args: argparse.Namespace) -> str:
    """``dtcosim run``: who speaks in an error line."""
    return f"dtcosim {args.command}" if args.command else "dtcosim"


def main(argv: list[str] | None = None) -> int:
    """Run one ``dtcosim`` command; returns its exit status.

    SIGTERM and SIGHUP end a command like Ctrl-C does (the run command stops
    cleanly, see :mod:`orchestrator.cosim.stop_requests`): one line on stderr and
    the status ``128 + signal`` (130 for Ctrl-C), at any stage, start-up included.
    No traceback reaches the user: an ``OSError`` no command explained (a full disk)
    is one line naming the file, an unexpected exception one line saying it is a bug
    (:data:`DEBUG_VARIABLE` shows its traceback); both exit 1.
    """
    args = argparse.Namespace(command=None)
    with _command_signals(), _warnings_as_lines(lambda: _prog(args)):
        argv = sys.argv[1:] if argv is None else list(argv)
        try:
            parser = build_parser(argv)
            args = parser.parse_args(argv)
            if not getattr(args, "func", None):
                parser.print_help()
                return 2
            return int(args.func(args) or 0)
        except DtcosimError as exc:
            print(f"{_prog(args)}: error: {exc}", file=sys.stderr)
            return 1
        except KeyboardInterrupt as exc:
            signum = getattr(exc, "signum", signal.SIGINT)
            text = str(exc) if getattr(exc, "signum", None) is not None else "interrupted by the user (Ctrl-C)"
            print(f"{_prog(args)}: {text}", file=sys.stderr)
            return 128 + int(signum)
        except OSError as exc:  # a full disk, a file-size limit: where a command has nothing more to say about it
            print(f"{_prog(args)}: error: {os_error_text(exc)}", file=sys.stderr)
            return 1
        except Exception as exc:  # a bug: one line, the traceback only when asked for
            if os.environ.get(DEBUG_VARIABLE):
                raise
            print(f"{_prog(args)}: internal error: {type(exc).__name__}: {exc} (a bug in dtcosim: please report it "
                  f"with the command; {DEBUG_VARIABLE}=1 shows the traceback)", file=sys.stderr)
            return 1


def end_process(status: int) -> None:
    """Leave the process with ``status`` once everything is written, without the interpreter's teardown.

    pythonfmu 0.7's shared library (loaded into this process for every FMU and
    never unloaded) releases Python objects from its C++ static destructors,
    which run after the interpreter has been finalised: glibc then sometimes
    aborts with "corrupted double-linked list" (exit status 134) although every
    result was written. So the console script runs the Python exit handlers
    itself (``atexit``: temporary folders of extracted FMUs, logging, weakref
    finalizers), flushes stdout and stderr and ends with ``os._exit``, which
    skips the interpreter's finalisation and the C++ destructors. Nothing is
    lost: every file was already written and closed (by temporary file and
    rename) and every FMU instance freed by then.
    """
    try:
        atexit._run_exitfuncs()
    finally:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except Exception:  # noqa: BLE001 - a closed pipe must not change the status
                pass
        os._exit(status)


#: the cyclic garbage collector's thresholds in a command's process (Python's default: 700, 10, 10)
COLLECTOR_THRESHOLDS = (50_000, 10, 10)


def console_main() -> None:
    """Entry point of the ``dtcosim`` console script: :func:`main`, then :func:`end_process`.

    The cyclic garbage collector runs less often than Python's default (:data:`COLLECTOR_THRESHOLDS`:
    after 50 000 net new container objects instead of 700). A command imports ~1000 modules, whose
    objects live to the end, and makes few reference cycles; with the default every 700 new objects
    start a pass, and the full passes over all of them cost ~0.15 s of a 1.8 s ``dtcosim run``
    (``benchmarks/bench_commands.py``). Cycles are still collected, later; a run holding many
    samples collects between its phases itself (:mod:`orchestrator.run.memory`).
    """
    gc.set_threshold(*COLLECTOR_THRESHOLDS)
    try:
        status = main()
    except SystemExit as exc:  # argparse errors and --help, --version
        code = exc.code
        status = code if isinstance(code, int) else (0 if code is None else 1)
        if not isinstance(code, (int, type(None))):
            print(code, file=sys.stderr)
    except KeyboardInterrupt:  # a signal before main's handlers were in place
        print("dtcosim: interrupted", file=sys.stderr)
        status = 130
    end_process(status)


if __name__ == "__main__":
    console_main()
