"""``dtcosim validate`` on any FMU: third-party FMUs pass, broken files are problems with a message, never a traceback."""

from __future__ import annotations

import zipfile

import pytest

from tests.helpers.reference_fmus import NAMES, reference_fmu
from tests.helpers.scenarios import dtcosim


def validate(paths, tmp_path):
    proc = dtcosim("validate", *str(paths).split(" "), cwd=tmp_path)
    assert "Traceback" not in proc.stdout + proc.stderr
    return proc


def test_every_reference_fmu_is_valid(tmp_path):
    proc = validate(" ".join(str(reference_fmu(name)) for name in NAMES), tmp_path)
    assert proc.returncode == 0, proc.stdout
    for name in NAMES:
        assert f"{name}.fmu: ok (FMI 2.0 co-simulation, Reference FMUs" in proc.stdout
    assert proc.stdout.count("binaries for linux64") == len(NAMES)


def _copy(source, target, change, rename=lambda name: name):
    with zipfile.ZipFile(source) as zin, zipfile.ZipFile(target, "w") as zout:
        for item in zin.infolist():
            data = change(item.filename, zin.read(item.filename))
            if data is not None:
                zout.writestr(rename(item.filename), data)
    return target


def _truncated(name, data):
    return data[: len(data) // 2] if name == "modelDescription.xml" else data


def _without_description(name, data):
    return None if name == "modelDescription.xml" else data


def test_broken_files_are_named_problems(tmp_path):
    not_zip = tmp_path / "text.fmu"
    not_zip.write_text("not an FMU")
    cut = tmp_path / "cut.fmu"
    cut.write_bytes(reference_fmu("Dahlquist").read_bytes()[:300])
    truncated = _copy(reference_fmu("Dahlquist"), tmp_path / "truncated.fmu", _truncated)
    missing = _copy(reference_fmu("Dahlquist"), tmp_path / "missing.fmu", _without_description)
    cases = ((not_zip, "not a zip archive, so not an FMU"), (cut, "not a zip archive"),
             (truncated, "modelDescription.xml, line"), (missing, "has no modelDescription.xml"))
    proc = validate(" ".join(str(path) for path, _ in cases), tmp_path)
    assert proc.returncode == 1
    reports = proc.stdout.split(str(tmp_path))[1:]  # one block per file, in the order given
    for (path, message), report in zip(cases, reports):
        assert report.startswith(f"/{path.name}: 1 problem(s)") and message in report, proc.stdout


def test_an_fmu_without_a_binary_for_this_platform_cannot_run_here(tmp_path):
    foreign = _copy(reference_fmu("Dahlquist"), tmp_path / "Dahlquist.fmu", lambda name, data: data,
                    lambda name: name.replace("binaries/linux64/Dahlquist.so", "binaries/win64/Dahlquist.dll"))
    proc = validate(foreign, tmp_path)
    assert proc.returncode == 1
    assert "no co-simulation binary for this platform (linux64: binaries/linux64/Dahlquist.so)" \
        in proc.stdout and "it has binaries for: win64" in proc.stdout


def _ssp(tmp_path, change=None):
    from tests.helpers.ssp_documents import feedthrough, real, ssd, write_ssp, zip_folder

    folder = write_ssp(tmp_path / "folder", ssd(f"""
  <ssd:System name="root">
    <ssd:Elements>{feedthrough("ft", real("Float64_continuous_input", "input"))}</ssd:Elements>
  </ssd:System>"""))
    if change is not None:
        change(folder / "resources" / "Feedthrough.fmu")
    return zip_folder(folder, tmp_path / "system.ssp")


def _no_binary(fmu):
    _copy(reference_fmu("Feedthrough"), fmu, lambda name, data: data,
          lambda name: name.replace("binaries/linux64/Feedthrough.so", "binaries/win64/Feedthrough.dll"))


@pytest.mark.parametrize("change, status, lines", [
    (None, 0, ["{ssp}: valid (1 FMUs, 0 connections, 6 recorded variables, 0 load event(s); stepping order ft;",
               "{ssp}!resources/Feedthrough.fmu: ok (FMI 2.0 co-simulation, Reference FMUs"]),
    (_no_binary, 1, ["{ssp}: 1 problem(s)",
                     "  - invalid scenario entry components.ft.fmu = '{ssp}!resources/Feedthrough.fmu': expected an "
                     "FMU this host can load (no co-simulation binary for this platform"]),
])
def test_an_ssp_is_validated_as_run_check_checks_it_and_every_fmu_in_it(tmp_path, capsys, change, status, lines):
    from orchestrator.commands import cli

    ssp = _ssp(tmp_path, change)
    assert cli.main(["validate", str(ssp)]) == status
    out = capsys.readouterr().out.splitlines()
    assert len(out) == len(lines), out
    for line, expected in zip(out, lines):
        assert line.startswith(expected.format(ssp=ssp)), out
    assert "modelDescription.xml" not in "".join(out)
