"""Commands that write files on a full disk: one line naming the file, nothing half-written left (issue 35.9).

The full disk is an ``OSError(ENOSPC)`` without a file name, raised by the writer after part of the file
(as a file object's ``write`` or ``close`` raises it).
"""

from __future__ import annotations

import errno

import pytest

from orchestrator.commands import cli
from orchestrator.reports import modal


@pytest.mark.parametrize("full_at", ["modes.csv", "campbell.csv"])
def test_modes_on_a_full_disk_names_the_file(tmp_path, monkeypatch, capsys, full_at):
    """``dtcosim modes`` said 'error: No space left on device' (its CSV writer's error names no file)."""
    real = modal.write_rows_csv

    def full(path, rows):
        if path.name.startswith(f".{full_at}."):  # the temporary file of the target
            path.write_text("mode,kind\n1,")
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(path, rows)

    monkeypatch.setattr(modal, "write_rows_csv", full)
    out = tmp_path / "m"
    assert cli.main(["modes", "--out", str(out)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"dtcosim modes: error: {out / full_at}: No space left on device"]
    assert not (out / full_at).exists() and not [p for p in out.iterdir() if p.name.startswith(".")]
