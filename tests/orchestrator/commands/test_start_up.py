"""Start-up of a command: only the module of the command that runs is imported; every command is still listed."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from orchestrator.commands import cli
from orchestrator.commands.catalogue import COMMANDS, help_line

COMMAND_MODULES = {c.module for c in COMMANDS}


def _imported_command_modules(argv: list[str]) -> list[str]:
    """The command modules a fresh interpreter has imported after building the parser for ``argv``."""
    code = ("import json, sys\nfrom orchestrator.commands import cli\n"
            f"cli.build_parser({argv!r})\n"
            f"print(json.dumps(sorted(m for m in sys.modules if m in {sorted(COMMAND_MODULES)!r})))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: c.name)
def test_only_the_module_of_the_command_that_runs_is_imported(command):
    assert _imported_command_modules([command.name, "--help"]) == [command.module]


@pytest.mark.parametrize("argv", [[], ["--help"], ["--version"], ["-h", "run"]])
def test_help_and_version_import_no_command_module(argv):
    assert _imported_command_modules(argv) == []


def test_the_help_lists_every_command_with_the_line_its_module_registers(capsys):
    with pytest.raises(SystemExit) as done:
        cli.main(["--help"])
    assert done.value.code == 0
    listing = " ".join(capsys.readouterr().out.split())
    full = cli.build_parser()  # every module registers its own sub-parser
    registered = {a.dest: a.help for a in full._subparsers._group_actions[0]._choices_actions}
    assert list(registered) == [c.name for c in COMMANDS]
    for command in COMMANDS:
        assert registered[command.name] == help_line(command.name)
        assert f"{command.name} {' '.join(command.help.split())}" in listing


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: c.name)
def test_every_command_shows_its_own_help(command, capsys):
    with pytest.raises(SystemExit) as done:
        cli.main([command.name, "--help"])
    assert done.value.code == 0
    assert capsys.readouterr().out.startswith(f"usage: dtcosim {command.name} ")


def test_an_unknown_command_is_refused_naming_every_command(capsys):
    with pytest.raises(SystemExit) as done:
        cli.main(["runn"])
    assert done.value.code == 2
    err = capsys.readouterr().err
    assert "invalid choice: 'runn'" in err and all(f"'{c.name}'" in err for c in COMMANDS)


@pytest.mark.parametrize("argv, name", [(["run", "x.toml"], "run"), (["--version", "run"], "run"),
                                        (["-h", "run"], None), ([], None), (["--help"], None),
                                        (["export-ssp", "--out", "a.ssp"], "export-ssp")])
def test_the_command_is_the_first_word_unless_help_comes_first(argv, name):
    assert cli.command_named(argv) == name


def test_the_console_script_collects_cycles_less_often_than_python_by_default(monkeypatch):
    import gc

    seen = {}
    monkeypatch.setattr(cli, "main", lambda: seen.setdefault("thresholds", gc.get_threshold()) and 0)
    monkeypatch.setattr(cli, "end_process", lambda status: seen.setdefault("status", status))
    before = gc.get_threshold()
    try:
        cli.console_main()
    finally:
        gc.set_threshold(*before)
    assert seen == {"thresholds": cli.COLLECTOR_THRESHOLDS, "status": 0}
    assert cli.COLLECTOR_THRESHOLDS[0] > 700 and gc.isenabled()
