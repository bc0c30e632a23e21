"""Declared runtime requirements: the range policy, the file format, the checks (fast, no FMU runs)."""

from __future__ import annotations

import sys
from importlib import metadata

import pytest

from fmus import requirements, runtime_guard
from fmus.requirements import (
    check_environment,
    from_environment,
    imported_modules,
    python_range,
    read_from_fmu,
    third_party_modules,
)
from fmus.runtime_guard import (
    PackageRequirement,
    RequirementsFormatError,
    RuntimeRequirements,
    format_requirements,
    parse_requirements,
)

REQ = RuntimeRequirements("Gearbox", (3, 11), (3, 12), "3.11.7",
                          (PackageRequirement("numpy", "numpy", (2, 4), (3,), "2.4.6"),
                           PackageRequirement("scikit-learn", "sklearn", (1, 5), (2,), "1.5.2")))


@pytest.mark.parametrize("version, expected", [
    ("2.4.6", ((2, 4), (3,))),
    ("1.17.1", ((1, 17), (2,))),
    ("2.5.0rc1", ((2, 5), (3,))),
    ("3", ((3, 0), (4,))),
])
def test_package_range_is_the_tested_minor_release_up_to_the_next_major(version, expected):
    assert requirements.tested_range(version) == expected


def test_python_range_is_the_build_minor_version():
    assert python_range((3, 11, 7)) == ((3, 11), (3, 12))
    assert python_range((3, 13, 0)) == ((3, 13), (3, 14))


def test_requirements_file_round_trips_and_pip_reads_its_package_lines():
    text = format_requirements(REQ, "a header\nof two lines")
    assert parse_requirements(text, "Gearbox") == REQ
    package_lines = [line.split("#")[0].strip() for line in text.splitlines() if line and not line.startswith("#")]
    assert package_lines == ["numpy>=2.4,<3", "scikit-learn>=1.5,<2"]
    assert "# requires-python: >=3.11,<3.12  (tested: 3.11.7)" in text
    assert REQ.summary() == "Python >=3.11,<3.12 with numpy>=2.4,<3, scikit-learn>=1.5,<2"


@pytest.mark.parametrize("text, match", [
    ("# requires-python: >=3.11,<3.12  (tested: 3.11.7)\nnumpy\n", r"line 2 'numpy': expected"),
    ("numpy>=2.4,<3  # tested: 2.4.6 (import numpy)\n", "no '# requires-python"),
])
def test_malformed_requirements_are_refused_naming_the_line(text, match):
    with pytest.raises(RequirementsFormatError, match=match):
        parse_requirements(text)


def test_third_party_modules_are_the_absolute_non_stdlib_non_embedded_imports(tmp_path):
    (tmp_path / "a.py").write_text("import numpy as np\nimport os, json\nfrom . import b\nfrom ..components import c\n")
    (tmp_path / "b.py").write_text("def f():\n    from scipy.linalg import lu_factor\n    import pythonfmu\n"
                                   "from components.model import x\nfrom __future__ import annotations\n")
    assert third_party_modules([tmp_path / "a.py", tmp_path / "b.py"]) == ("numpy", "scipy")


def test_optional_notes_are_read_and_a_changed_file_is_read_again(tmp_path):
    (tmp_path / "a.py").write_text("import numpy\nimport scipy  # optional requirement: faster solves\n")
    assert imported_modules([tmp_path / "a.py"]) == ({"numpy": None}, {"scipy": "faster solves"})
    assert imported_modules([tmp_path / "a.py"])[0] == {"numpy": None}
    (tmp_path / "a.py").write_text("import pandas\n")
    assert imported_modules([tmp_path / "a.py"]) == ({"pandas": None}, {})


def test_requirements_come_from_the_installed_versions():
    req = from_environment("X", ["sklearn", "numpy"], python=(3, 12, 4),
                           version_of={"numpy": "2.4.6", "scikit-learn": "1.5.2"}.__getitem__,
                           distribution={"numpy": "numpy", "sklearn": "scikit-learn"}.__getitem__)
    assert req.python_specifier == ">=3.12,<3.13" and req.python_tested == "3.12.4"
    assert [(p.distribution, p.module, p.specifier, p.tested) for p in req.packages] == [
        ("numpy", "numpy", "numpy>=2.4,<3", "2.4.6"), ("scikit-learn", "sklearn", "scikit-learn>=1.5,<2", "1.5.2")]


def test_built_fmus_declare_exactly_what_their_code_imports(built_fmus):
    for name, built in built_fmus.items():
        req = read_from_fmu(built.path)
        assert [(p.distribution, p.tested) for p in req.packages] == [("numpy", metadata.version("numpy"))], name
        assert req.python_tested == ".".join(map(str, sys.version_info[:3]))


def _found(*missing):
    return lambda module: None if module in missing else object()


def test_environment_check_names_what_is_missing_and_what_is_untested():
    ok = check_environment(REQ, (3, 11, 2), _found(), lambda p: {"numpy": "2.4.0", "scikit-learn": "1.9"}[p.distribution])
    assert ok.missing == () and ok.warnings == ()
    check = check_environment(REQ, (3, 10, 13), _found("sklearn"), lambda p: "3.0.1")
    assert check.missing == (
        "it requires Python >=3.11,<3.12 (tested with 3.11.7) but the host process runs "
        f"{runtime_guard.interpreter()}",
        "module 'sklearn' not found: install scikit-learn>=1.5,<2 (tested with 1.5.2)",
    )
    assert check.warnings == ("numpy 3.0.1 is outside the tested range numpy>=2.4,<3 (tested with 2.4.6)",)
    newer = check_environment(REQ, (3, 13, 0), _found(), lambda p: "2.4.6" if p.module == "numpy" else "1.5.0")
    assert newer.missing == ()
    assert newer.warnings == ("Python 3.13.0 is outside the tested range >=3.11,<3.12 (tested with 3.11.7)",)


def test_guard_turns_an_import_failure_into_a_message_naming_the_module(tmp_path, capsys):
    (tmp_path / "requirements.txt").write_text(format_requirements(REQ))
    entry = tmp_path / "_entry.py"

    def importer():
        raise ModuleNotFoundError("No module named 'sklearn'", name="sklearn")

    with pytest.raises(ImportError, match=r"dtcosim Gearbox FMU cannot start: Python module 'sklearn' cannot be "
                                          r"imported \(ModuleNotFoundError: No module named 'sklearn'\); the FMU "
                                          r"requires Python >=3.11,<3.12 with numpy>=2.4,<3, scikit-learn>=1.5,<2") as info:
        runtime_guard.load_slave("Gearbox", str(entry), importer)
    assert info.value.name == "sklearn"
    assert str(info.value) in capsys.readouterr().err  # also on stderr, for hosts without logging


def test_guard_returns_the_slave_and_warns_about_untested_versions(tmp_path, capsys, monkeypatch):
    req = RuntimeRequirements("Toy", (3, 0), (3, 1), "3.0.0", (PackageRequirement("numpy", "numpy", (1, 0), (1, 1), "1.0.0"),))
    (tmp_path / "requirements.txt").write_text(format_requirements(req))
    monkeypatch.setattr(runtime_guard, "_reported", set())
    monkeypatch.setattr(runtime_guard, "_warnings", [])
    assert runtime_guard.load_slave("Toy", str(tmp_path / "_entry.py"), lambda: int) is int
    warnings = runtime_guard.warnings()
    assert any(w.startswith("dtcosim Toy FMU: Python ") and "outside the tested range >=3.0,<3.1" in w for w in warnings)
    assert any(f"numpy {metadata.version('numpy')} is outside the tested range numpy>=1.0,<1.1" in w for w in warnings)
    assert "[warning] dtcosim Toy FMU" in capsys.readouterr().err


def test_guard_refuses_an_older_python_before_importing(tmp_path, capsys):
    req = RuntimeRequirements("Future", (3, 99), (3, 100), "3.99.0", ())
    (tmp_path / "requirements.txt").write_text(format_requirements(req))
    imported = []
    with pytest.raises(ImportError, match=r"dtcosim Future FMU cannot start: it requires Python >=3.99,<3.100"):
        runtime_guard.load_slave("Future", str(tmp_path / "_entry.py"), lambda: imported.append(1))
    assert imported == []


def test_an_import_marked_optional_is_an_optional_requirement(tmp_path):
    (tmp_path / "a.py").write_text("import numpy\nfrom numba import njit  # optional requirement: a faster path\n")
    (tmp_path / "b.py").write_text("import numpy as np\nimport scipy.linalg  # optional requirement: x\nimport scipy\n")
    required, optional = imported_modules([tmp_path / "a.py", tmp_path / "b.py"])
    assert list(required) == ["numpy", "scipy"]  # scipy also imported without the note: required
    assert optional == {"numba": "a faster path"}


def test_optional_requirements_round_trip_and_are_only_warnings(tmp_path):
    req = from_environment("X", ["numpy"], python=(3, 11, 7), version_of=lambda d: {"numpy": "2.4.6", "numba": "0.68.1"}[d],
                           distribution=lambda m: m, optional={"numba": "the compiled kernel"})
    text = format_requirements(req)
    assert "# optional: numba>=0.68,<1  # tested: 0.68.1 (import numba) the compiled kernel" in text
    assert not any(line.startswith("numba") for line in text.splitlines())  # pip -r installs only what is required
    again = parse_requirements(text, "X")
    assert again == req and again.summary().endswith("(optional: numba>=0.68,<1)")
    check = check_environment(again, python=(3, 11, 7), find_module=lambda m: None if m == "numba" else object(),
                              installed=lambda p: "2.4.6")
    assert check.missing == () and any("optional module 'numba' not found" in w for w in check.warnings)


@pytest.mark.parametrize("module", ["numpy", "scipy", "pythonfmu", "fmpy", "PIL", "matplotlib", "_distutils_hack"])
def test_the_distribution_of_a_module_is_what_every_installed_file_list_says(module):
    from fmus.requirements import distribution_of

    assert distribution_of(module) == metadata.packages_distributions()[module][0]
