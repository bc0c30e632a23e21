"""Studies: sizes, seeds and addresses checked before anything runs; a hand-edited journal never breaks --report;
an SSP that would expand to gigabytes is refused; export-ssp checks like run."""

from __future__ import annotations

import json
import zipfile

import pytest

from orchestrator.commands.cli import main
from orchestrator.errors import SspError
from orchestrator.inputs.study import StudyError
from orchestrator.inputs.study_file import load_study
from tests.helpers.studies import SMALL_HEAD, SMALL_STUDY, SMALL_TABLES

COSIM_SEEDS = """
name = "seeds"
engine = "cosim"
measures = ["wind.omega:std"]
seeds = {seeds}
[base]
scenario = "paper-60s"
[simulation]
stop = 0.1
window = [0.0, 0.1]
"""


@pytest.mark.parametrize("axes, expected", [
    ("[[axes]]\nparameter = \"gearbox.R1\"\nstart = 6.0\nstop = 10.0\nnum = 1000000000\n",
     "axes[0].num = 1000000000: expected an integer within [1, 100000]"),
    ("[[axes]]\nparameter = \"gearbox.R1\"\nstart = 6.0\nstop = 10.0\nnum = 1000\n"
     "[[axes]]\nparameter = \"gearbox.stage3.lambda\"\nstart = 1e5\nstop = 1e6\nnum = 1001\n",
     "axes = '1 x 1000 x 1001 x 1': expected a study of at most 1,000,000 points"),
])
def test_study_sizes_are_bounded_before_any_point_is_made(write_study, axes, expected):
    path = write_study(SMALL_HEAD + SMALL_TABLES + axes)
    with pytest.raises(StudyError) as info:
        load_study(path)
    assert expected in str(info.value)


def test_a_grid_of_many_axes_is_counted_before_any_axis_value_exists(write_study):
    """Issue 35.7: 30 axes of 100 000 values each allocated 3 million values before the study counted its points."""
    import tracemalloc

    axes = "".join(f"[[axes]]\nparameter = \"gearbox.p{i}\"\nstart = 1.0\nstop = 2.0\nnum = 100000\n"
                   for i in range(30))
    path = write_study(SMALL_HEAD + SMALL_TABLES + axes)
    tracemalloc.start()
    try:
        with pytest.raises(StudyError, match=r"axes = '30 axes': expected a study of at most 1,000,000 points "
                                             r"\(explicit points x axes x seeds\); this one has more than 1,000,000"):
            load_study(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 20e6, peak  # the values would take ~100 MB


def test_seeds_beyond_an_fmi_integer_are_refused_at_check(fmu_dir, write_study, capsys):
    path = write_study(COSIM_SEEDS.format(seeds="[1, 4294967297, 8589934593]"))
    assert main(["sweep", str(path), "--check", "--fmu-dir", str(fmu_dir)]) == 1
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.endswith("invalid study entry seeds[1] (wind.seed) = 4294967297: expected an FMI Integer within "
                        "[-2147483648, 2147483647] (32 bits) for wind.seed (point 1)")


def test_a_value_outside_the_fmus_bounds_is_refused_at_check(fmu_dir, write_study, capsys):
    path = write_study(COSIM_SEEDS.format(seeds="[1]") + '[[axes]]\nparameter = "gearbox.stage1.k0"\n'
                                                        'values = [-1.0, 1.58e10]\n')
    assert main(["sweep", str(path), "--check", "--fmu-dir", str(fmu_dir)]) == 1
    assert capsys.readouterr().err.strip().endswith(
        "axes[0].values[0] (gearbox.stage1.k0) = -1.0: expected > 0 (within [1e-30, 1e+30]) for gearbox.stage1.k0 "
        "(point 0)")


@pytest.mark.parametrize("address", ["not a url", "tcp://127.0.0.1:1"])
def test_a_bad_scheduler_address_is_a_named_error(write_study, tmp_path, capsys, monkeypatch, address):
    import orchestrator.study.cluster as cluster

    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT_S", 2.0)  # a refused port: no need to wait the default 20 s
    path = write_study(SMALL_STUDY)
    status = main(["sweep", str(path), "--scheduler", address, "--out", str(tmp_path / "out"), "-q"])
    err = capsys.readouterr().err
    assert status == 1 and "Traceback" not in err
    assert f"invalid study entry --scheduler = '{address}'" in err


def test_a_journal_record_without_a_status_does_not_break_the_report(write_study, tmp_path, capsys):
    path = write_study(SMALL_STUDY)
    out = tmp_path / "out"
    assert main(["sweep", str(path), "--workers", "1", "--out", str(out), "-q", "--no-plots"]) == 0
    journal = out / "journal.jsonl"
    records = [json.loads(line) for line in journal.read_text().splitlines()]
    edited = dict(records[0])
    del edited["status"]
    with open(journal, "a") as fh:
        fh.write(json.dumps(edited) + "\n")  # a newer record of point 0, without its status
    assert main(["sweep", str(path), "--report", "--out", str(out), "--no-plots"]) == 0
    table = (out / "results.csv").read_text().splitlines()
    assert table[1].split(",")[1] == "ok"  # the record without a status is skipped: point 0 keeps its result


def test_an_ssp_that_would_expand_to_gigabytes_is_refused(tmp_path):
    from orchestrator.interop.ssp import import_ssp

    bomb = tmp_path / "bomb.ssp"
    with zipfile.ZipFile(bomb, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("SystemStructure.ssd", "<ssd/>")
        with zf.open("resources/zeros.bin", "w", force_zip64=True) as member:
            chunk = b"\0" * (1 << 24)
            for _ in range(80):  # 1.25 GiB of zeros, a few MB compressed
                member.write(chunk)
    assert bomb.stat().st_size < 10 << 20
    with pytest.raises(SspError, match=r"bomb.ssp: expands to 1280 MiB, expected at most 1024 MiB"):
        import_ssp(bomb)


def test_export_ssp_checks_the_values_like_run(fmu_dir, tmp_path, capsys):
    status = main(["export-ssp", "--fmu-dir", str(fmu_dir), "--out", str(tmp_path / "x.ssp"),
                   "--set", "gearbox.stage1.k0=-1"])
    assert status == 1
    assert capsys.readouterr().err.strip().endswith("expected > 0 (within [1e-30, 1e+30])")
    assert not (tmp_path / "x.ssp").exists()
