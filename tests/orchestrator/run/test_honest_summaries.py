"""A run that ends never leaves a summary saying "running" (issue 35.4): a stop signal just after the output folder
is prepared, a second signal, a full disk; a killed run's files are cleared by the next run (issue 35.6).

Signals are raised by the process itself at a chosen point (``signal.raise_signal`` after the folder is prepared),
and the full disk is :class:`tests.helpers.failing_files.FullDisk` in place of ``write_summary``: both
deterministic.
"""

from __future__ import annotations

import json
import os
import signal

import pytest

from orchestrator.commands import cli
from orchestrator.run import run_folder
from tests.helpers.stop_signals import ignored_stop_signals_at_defaults
from orchestrator.run.run_folder import OutputFolderError, RunFolder
from tests.helpers.failing_files import FullAt, FullDisk


def summary_of(out):
    return json.loads((out / "summary.json").read_text())


@pytest.fixture
def signal_after_prepare(monkeypatch):
    """``arm(signum)``: the run receives ``signum`` right after its output folder is prepared."""

    def arm(signum):
        real = RunFolder.prepare.__func__

        def prepare(cls, *args, **kwargs):
            folder = real(cls, *args, **kwargs)
            signal.raise_signal(signum)  # handled (or not) before the next instruction of the run
            return folder

        monkeypatch.setattr(RunFolder, "prepare", classmethod(prepare))

    return arm


@pytest.mark.parametrize("signum, status", [(signal.SIGTERM, 143), (signal.SIGINT, 130), (signal.SIGHUP, 129)])
def test_a_signal_just_after_the_folder_is_prepared_ends_with_a_stopped_summary(toy_scenario, tmp_path, capsys,
                                                                                 signal_after_prepare, signum, status):
    signal_after_prepare(signum)
    out = tmp_path / "out"
    with ignored_stop_signals_at_defaults():  # a suite under nohup ignores SIGHUP, and so would the command
        assert cli.main(["run", str(toy_scenario()), "--out", str(out), "--no-build", "-q"]) == status
    summary = summary_of(out)
    assert summary["status"] == "stopped" and summary["complete"] is False and summary["interrupted"] is True
    assert summary["signal"] == signal.Signals(signum).name and summary["samples"] == 0
    assert sorted(p.name for p in out.iterdir()) == ["summary.json"]
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "interrupted" in err[0] and "summary.json says so" in err[0], err


def test_an_exception_that_ends_the_run_leaves_a_summary_that_says_so(toy_scenario, tmp_path, monkeypatch):
    """A second signal (RunInterrupted raised at once) or a bug: the summary tells how the run ended."""
    from orchestrator.cosim.system import resolve_system
    from orchestrator.errors import RunInterrupted
    from orchestrator.inputs.scenario_file import load_scenario
    from orchestrator.run import runner

    def insist(*args, **kwargs):
        raise RunInterrupted(signal.SIGTERM, "the summary")

    system = resolve_system(load_scenario(toy_scenario()))
    out = tmp_path / "out"
    monkeypatch.setattr(runner, "build_summary", insist)
    with pytest.raises(RunInterrupted):
        runner.run_scenario(system, out)
    summary = summary_of(out)
    assert summary["status"] == "stopped" and summary["signal"] == "SIGTERM" and summary["complete"] is False
    assert summary["error"] == "interrupted by SIGTERM during the summary"
    assert summary["files"] == {"timeseries": "timeseries.csv", "summary": "summary.json"}
    assert "files_being_written" not in summary
    monkeypatch.setattr(runner, "build_summary", lambda *args, **kwargs: 1 / 0)
    with pytest.raises(ZeroDivisionError):
        runner.run_scenario(system, out)
    summary = summary_of(out)
    assert summary["status"] == "failed" and summary["error"] == "ZeroDivisionError: division by zero"


def test_a_completely_full_disk_is_refused_before_anything_runs(toy_scenario, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(run_folder, "write_summary", FullDisk())
    out = tmp_path / "out"
    assert cli.main(["run", str(toy_scenario()), "--out", str(out), "--no-build", "-q"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"dtcosim run: error: invalid command-line entry --out = '{out}': expected a folder with room "
                   f"for the results (cannot write {out / 'summary.json'}: No space left on device)"]
    assert list(out.iterdir()) == []  # no summary: nothing ran


def _whole(summary, old_there):
    return "statistics" in summary  # the whole summary does not fit


def _short_only_without_the_old(summary, old_there):
    return "statistics" in summary or (old_there and summary["status"] != "running")


@pytest.mark.parametrize("refuse, refused", [
    (_whole, 1),                        # the short summary fits beside the running one
    (_short_only_without_the_old, 2),   # it fits only in the room the running summary frees
])
def test_a_disk_too_full_for_the_whole_summary_keeps_a_short_honest_one(toy_scenario, tmp_path, monkeypatch, capsys,
                                                                       refuse, refused):
    disk = FullDisk(refuse)
    monkeypatch.setattr(run_folder, "write_summary", disk)
    out = tmp_path / "out"
    assert cli.main(["run", str(toy_scenario()), "--out", str(out), "--no-build", "-q"]) == 1
    summary = summary_of(out)
    assert summary["status"] == "failed" and summary["complete"] is True and summary["samples"] == 11
    assert summary["files"] == {"timeseries": "timeseries.csv", "summary": "summary.json"}
    assert "statistics" not in summary and "versions" not in summary
    assert summary["problems"] == [f"summary.json shortened to the run's status and files (cannot write "
                                   f"{out / 'summary.json'}: No space left on device)"]
    assert disk.refused == refused
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"dtcosim run: error: {summary['problems'][0]}"]


def test_no_room_even_for_the_short_summary_leaves_none(tmp_path, monkeypatch):
    folder = RunFolder.prepare(tmp_path / "out", {"scenario": "a"})
    monkeypatch.setattr(run_folder, "write_summary", FullDisk())
    with pytest.raises(OSError, match="No space left on device"):
        folder.finish({"scenario": "a", "status": "complete", "complete": True, "statistics": {}})
    folder.release()
    assert list((tmp_path / "out").iterdir()) == []  # the running summary would lie: removed


@pytest.mark.parametrize("full_at, kept, not_done", [
    ("load_duration.png", ["contact_loss", "fatigue_del", "fatigue_ldd"], ["the rest of analyses", "plots"]),
    ("generator_speed.png", ["contact_loss", "fatigue_del", "fatigue_ldd", "plot:load_duration", "plot:rotor_speed"],
     ["the rest of plots"]),
])
def test_a_full_disk_during_the_analyses_or_plots_keeps_what_was_written_and_says_what_was_not(
        fmu_dir, tmp_path, monkeypatch, capsys, full_at, kept, not_done):
    """A disk that filled at a plot: the whole CSVs written before it were removed as never listed, the analyses'
    results left the summary, and the run said "not done: " with nothing after it (seen on a 100 kB tmpfs)."""
    monkeypatch.setattr(os, "replace", FullAt(full_at))
    out = tmp_path / "out"
    assert cli.main(["run", "--fmu-dir", str(fmu_dir), "--no-build", "--stop", "0.5", "--out", str(out), "-q"]) == 1
    summary = summary_of(out)
    assert sorted(summary["files"]) == sorted(["timeseries", *kept, "summary"])
    assert sorted(p.name for p in out.iterdir()) == sorted(summary["files"].values())
    assert "contact_loss" in summary and "fatigue" in summary  # what the analyses computed
    problem = f"cannot write {out / full_at}: No space left on device"
    assert summary["post_processing"] == {"stopped": f"stopped: {problem}", "not_done": not_done, "error": problem}
    assert summary["problems"] == [problem] and summary["status"] == "failed"
    errors = [line for line in capsys.readouterr().err.splitlines() if "error" in line]
    assert errors == [f"dtcosim run: error: {problem}; not done: {', '.join(not_done)}"]


def test_a_file_written_into_the_folder_is_named_in_the_summary_before_it_appears(tmp_path, monkeypatch):
    """Issue 35.6: killed between writing a plot and listing it, the next run still knows the plot is a run's."""
    from orchestrator.atomic_files import write_bytes_atomic

    out = tmp_path / "out"
    first = RunFolder.prepare(out, {"scenario": "seed-1", "complete": False})
    (out / "my-notes.txt").write_text("not a run's")
    real_replace = os.replace

    class Killed(BaseException):
        pass

    def replace_then_die(src, dst):
        real_replace(src, dst)
        if str(dst).endswith(".png"):
            raise Killed  # the process dies here: the plot is in place, its stage never listed it

    monkeypatch.setattr(os, "replace", replace_then_die)
    with pytest.raises(Killed):
        write_bytes_atomic(out / "rotor_speed.png", b"seed 1")
    monkeypatch.undo()
    assert summary_of(out)["files_being_written"] == ["rotor_speed.png"] and summary_of(out)["status"] == "running"
    first.release()  # the lock goes with the killed process
    second = RunFolder.prepare(out, {"scenario": "seed-7"})
    assert sorted(p.name for p in out.iterdir()) == ["my-notes.txt", "summary.json"]
    assert second.replaced == ["rotor_speed.png"]
    second.release()


def test_a_file_a_failed_stage_wrote_but_never_listed_is_removed_when_the_run_ends(tmp_path):
    from orchestrator.atomic_files import write_bytes_atomic

    out = tmp_path / "out"
    folder = RunFolder.prepare(out, {"scenario": "a"})
    write_bytes_atomic(out / "listed.csv", b"1")
    folder.commit("table", out / "listed.csv")
    write_bytes_atomic(out / "orphan.png", b"2")  # its stage failed before listing it
    folder.finish({"scenario": "a", "status": "failed", "complete": False, **folder.listing()})
    folder.release()
    assert sorted(p.name for p in out.iterdir()) == ["listed.csv", "summary.json"]
    write_bytes_atomic(out / "after.txt", b"3")  # once released, the folder is claimed no more
    assert "files_being_written" not in summary_of(out)


def test_a_signal_with_a_results_file_not_written_is_not_told_as_a_whole_run(toy_scenario, tmp_path, monkeypatch,
                                                                            capsys):
    """Issue 35.5: a Ctrl-C and a failed Parquet conversion; stderr said the folder "holds the whole run"."""
    from orchestrator.run import parquet_writer

    def interrupted_conversion(stream, parquet, where="auto"):
        signal.raise_signal(signal.SIGINT)  # the run's stop handling takes it
        raise OSError(f"{parquet}: the Parquet conversion of {stream.name} was killed by signal 2: KeyboardInterrupt")

    monkeypatch.setattr(parquet_writer, "convert_stream", interrupted_conversion)
    out = tmp_path / "out"
    assert cli.main(["run", str(toy_scenario()), "--out", str(out), "--no-build", "-q", "--results", "parquet"]) == 130
    summary = summary_of(out)
    assert summary["status"] == "failed" and summary["files"] == {"summary": "summary.json"}
    assert summary["files_incomplete"]["timeseries"]["file"] == "timeseries.parquet.partial"
    assert sorted(p.name for p in out.iterdir()) == ["summary.json", "timeseries.parquet.partial"]
    err = capsys.readouterr().err
    assert "holds the whole run" not in err
    assert err.strip().splitlines()[-1] == (f"dtcosim run: interrupted (SIGINT); the co-simulation completed but not "
                                            f"every result was written: {out} holds part of the run "
                                            f"({out / 'summary.json'} lists what it holds)")


# a paper run killed (os._exit, as SIGKILL: no handler, no summary update) right after its first plot is in place
KILLED_AFTER_A_PLOT = """
import os, sys
sys.path.insert(0, {root!r})
real_replace = os.replace

def replace_then_die(src, dst):
    real_replace(src, dst)
    if str(dst).endswith(".png"):
        os._exit(137)

os.replace = replace_then_die
from orchestrator.commands import cli
cli.end_process(cli.main(["run", "--fmu-dir", {fmus!r}, "--out", {out!r}, "--stop", "6", "-q",
                          "--set", "wind.seed=1"]))
"""


@pytest.mark.slow
def test_a_run_killed_after_writing_a_plot_leaves_nothing_for_the_next_run_to_mix(fmu_dir, tmp_path):
    """Issue 35.6: a seed-1 rotor_speed.png survived beside the seed-7 results of the next run into the folder."""
    import subprocess
    import sys
    from pathlib import Path

    from tests.helpers.scenarios import dtcosim

    out = tmp_path / "out"
    root = str(Path(__file__).resolve().parents[3])
    killed = subprocess.run([sys.executable, "-c", KILLED_AFTER_A_PLOT.format(root=root, fmus=str(fmu_dir),
                                                                              out=str(out))],
                            capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert killed.returncode == 137, killed.stderr
    plots = [p.name for p in out.glob("*.png")]
    assert plots and set(plots) <= set(summary_of(out)["files_being_written"])  # named before it appeared
    again = dtcosim("run", "--fmu-dir", str(fmu_dir), "--out", str(out), "--stop", "0.5", "--no-plots", "-q",
                    "--set", "wind.seed=7", cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    summary = summary_of(out)
    assert summary["status"] == "complete" and summary["fmus"]["wind"]["parameters"]["seed"] == 7
    assert sorted(p.name for p in out.iterdir()) == sorted(summary["files"].values())  # nothing of seed 1 left
