"""Stop signals kept out of imports: a Ctrl-C during start-up is one line and 130, never an ImportError."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from orchestrator.import_safe_signals import inside_import

ROOT = Path(__file__).resolve().parents[2]

# a module whose import receives a signal and then runs Python code for a while; like numpy's C extensions,
# it turns whatever interrupts it into an ImportError
SIGNALLED_MODULE = textwrap.dedent("""
    import os, signal, time
    try:
        signal.raise_signal(getattr(signal, os.environ["SIGNAL"]))
        total = 0
        end = time.monotonic() + 0.2
        while time.monotonic() < end:
            total += 1
    except BaseException as exc:
        raise ImportError("PyCapsule_Import could not import module 'signalled'") from exc
    IMPORTED = True
""")


def _python(code: str, tmp_path: Path, signame: str = "SIGINT") -> subprocess.CompletedProcess:
    (tmp_path / "signalled.py").write_text(SIGNALLED_MODULE)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT)]), "SIGNAL": signame}
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=30)


def test_inside_import_sees_the_import_machinery(tmp_path, monkeypatch):
    (tmp_path / "probe_import_frame.py").write_text(
        "import sys\nfrom orchestrator.import_safe_signals import inside_import\nSEEN = inside_import(sys._getframe())\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    import probe_import_frame

    assert probe_import_frame.SEEN is True
    assert inside_import(sys._getframe()) is False
    assert inside_import(None) is False


@pytest.mark.parametrize("wrapped, expected", [
    (True, "interrupted after the import: True"),  # delivered again once the import is over
    (False, "interrupted inside the import"),      # what the wrapper prevents: the import breaks off
])
def test_a_signal_during_an_import_is_delivered_after_it(tmp_path, wrapped, expected):
    proc = _python(f"""
        import signal, sys, time
        from orchestrator.import_safe_signals import outside_imports
        if {wrapped}:
            signal.signal(signal.SIGINT, outside_imports(signal.default_int_handler))
        try:
            import signalled
        except ImportError:
            print("interrupted inside the import")
            sys.exit(0)
        try:
            time.sleep(60)  # the signal must wake the main thread: the test times out otherwise
        except KeyboardInterrupt:
            print("interrupted after the import:", signalled.IMPORTED)
    """, tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == expected


# a subcommand whose module is imported (only when it runs) while the parser is built and receives the signal there
SLEEP_COMMAND = textwrap.dedent("""
    import time
    import signalled  # the stop signal lands in this import

    def register(sub):
        p = sub.add_parser("sleep")
        p.set_defaults(func=lambda args: time.sleep(60) or 0)
""")


@pytest.mark.parametrize("signame, status, line", [
    # the command is named once the arguments are parsed; the signal may land before or after
    ("SIGINT", 130, r"dtcosim( sleep)?: interrupted by the user \(Ctrl-C\)"),
    ("SIGTERM", 143, r"dtcosim( sleep)?: interrupted by SIGTERM during the command"),
])
def test_a_stop_signal_during_start_up_is_one_line_and_its_status(tmp_path, signame, status, line):
    (tmp_path / "sleep_command.py").write_text(SLEEP_COMMAND)
    proc = _python("""
        from orchestrator.commands import cli
        from orchestrator.commands.catalogue import Command
        cli.COMMANDS = cli.COMMANDS + (Command("sleep", "sleep_command", "sleep a minute"),)
        cli.end_process(cli.main(["sleep"]))
    """, tmp_path, signame)
    assert proc.returncode == status, proc.stderr
    assert re.fullmatch(line, proc.stderr.strip()), proc.stderr


def test_a_signal_the_process_ignores_stays_ignored_during_a_command(monkeypatch):
    from orchestrator.commands import cli
    from orchestrator.commands.catalogue import Command as Entry

    seen = {}

    class Command:
        @staticmethod
        def register(sub):
            p = sub.add_parser("probe")
            p.set_defaults(func=lambda args: seen.update(hup=signal.getsignal(signal.SIGHUP),
                                                         term=signal.getsignal(signal.SIGTERM)) or 0)

    monkeypatch.setattr(cli, "COMMANDS", (Entry("probe", "probe_command", "probe the signal handlers"),))
    monkeypatch.setitem(sys.modules, "probe_command", Command)
    before_term = signal.getsignal(signal.SIGTERM)
    previous = signal.signal(signal.SIGHUP, signal.SIG_IGN)  # as under nohup
    try:
        assert cli.main(["probe"]) == 0
        assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGHUP, previous)
    assert seen["hup"] is signal.SIG_IGN
    assert seen["term"].wrapped is cli._raise_interrupt  # a handler that ends the command, kept out of imports
    assert signal.getsignal(signal.SIGTERM) is before_term  # restored afterwards


def test_a_deferred_signal_is_sent_again_until_its_handler_has_run(monkeypatch):
    """One send can be lost (it lands just before the main thread blocks in a sleep or a wait): repeat until
    handled, and a signal deferred again while one redelivery is under way starts no second one."""
    import threading
    import time

    from orchestrator import import_safe_signals as iss

    sent = []
    monkeypatch.setattr(iss, "REDELIVERY_S", 0.005)
    monkeypatch.setattr(iss, "_to_main_thread", sent.append)
    starts, timer = [], threading.Timer
    monkeypatch.setattr(iss.threading, "Timer", lambda *a: starts.append(a) or timer(*a))
    handled = []
    deferring = iss.outside_imports(lambda signum, frame: handled.append(signum))
    previous = signal.signal(signal.SIGUSR1, deferring)
    try:
        iss._deliver_again(signal.SIGUSR1)
        iss._deliver_again(signal.SIGUSR1)  # deferred again inside the import: no second redelivery
        deadline = time.monotonic() + 10
        while len(sent) < 3 and time.monotonic() < deadline:  # the first sends "lost": the handler never ran
            time.sleep(0.005)
        assert len(sent) >= 3 and set(sent) == {signal.SIGUSR1} and len(starts) == 1
        deferring(signal.SIGUSR1, None)  # finally outside any import
        count = len(sent)
        time.sleep(0.05)
    finally:
        signal.signal(signal.SIGUSR1, previous)
    assert handled == [signal.SIGUSR1] and len(sent) <= count + 1  # at most the send under way
    assert signal.SIGUSR1 not in iss._pending


def test_a_signal_deferred_when_its_handler_is_restored_reaches_the_restored_one_once(monkeypatch):
    """The command ended (its handlers restored) before the deferred signal was handled: it goes, once, to the
    handler in place, as it would have without the deferral; no stream of signals to a handler that never clears it."""
    import time

    from orchestrator import import_safe_signals as iss

    sent = []
    monkeypatch.setattr(iss, "REDELIVERY_S", 0.005)
    monkeypatch.setattr(iss, "_to_main_thread", sent.append)
    previous = signal.signal(signal.SIGUSR1, lambda signum, frame: None)  # no deferring handler in place
    try:
        iss._deliver_again(signal.SIGUSR1)
        deadline = time.monotonic() + 10
        while signal.SIGUSR1 in iss._pending and time.monotonic() < deadline:
            time.sleep(0.005)
        time.sleep(0.05)
    finally:
        signal.signal(signal.SIGUSR1, previous)
    assert sent == [signal.SIGUSR1] and signal.SIGUSR1 not in iss._pending
