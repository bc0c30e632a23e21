"""Building the FMUs: validity, interface, units, self-containment, CLI."""

from __future__ import annotations

import json
import math
import shutil
import sys
import zipfile
from xml.etree import ElementTree as ET

import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from components.model.description import build
from components.model.presets import cosim_preset
from fmus import build as fmu_build
from fmus import bytecode
from fmus.build import (
    BuildError,
    SourceTree,
    code_hash,
    drivetrain_of_preset,
    embedded_modules,
    rewrite_slave_imports,
)
from fmus.model_description import read_member, rewrite_archive
from fmus.registry import kind
from fmus.runtime_files import GUARD_FILE
from fmus.validation import check_fmu
from orchestrator.commands.cli import main as dtcosim
from tests.helpers.fmu_hosts import load_driver, run_python

FMU_NAMES = ("WindSource", "Gearbox", "GeneratorRotor")


def variables(path):
    return {v.name: v for v in read_model_description(str(path)).modelVariables}


@pytest.mark.parametrize("name", FMU_NAMES)
def test_fmpy_validation_reports_no_problem(fmu_path, name):
    assert validate_fmu(str(fmu_path(name))) == []
    assert check_fmu(fmu_path(name)) == []


@pytest.mark.parametrize("old, new", [
    (None, None),  # as built: plain structured names
    ('name="stage1.k0"', 'name="stage1..k0"'),  # illegal
    ('name="stage1.k0"', 'name="stage1.\'k 0\'"'),  # quoted: legal, parsed by fmpy
    ('name="stage1.k0"', 'name="shaft1.torque"'),  # a duplicate
    ('<Unknown index=', '<Unknown index="9999" x='),  # a model structure entry of no variable
])
def test_the_build_finds_what_fmpys_validation_finds(fmu_path, tmp_path, old, new):
    from fmus.validation import fmpy_problems

    fmu = tmp_path / "Gearbox.fmu"
    shutil.copy(fmu_path("Gearbox"), fmu)
    if old is not None:
        xml = read_member(fmu).decode()
        assert old in xml
        rewrite_archive(fmu, {"modelDescription.xml": xml.replace(old, new, 1).encode()})
    expected = validate_fmu(str(fmu))
    assert fmpy_problems(fmu) == expected
    assert (expected == []) == (old is None or "'" in new)


@pytest.mark.parametrize("name, causality, expected", [
    ("WindSource", "output", {"omega": "rad/s", "phi": "rad"}),
    ("WindSource", "parameter", {"omega0": "rad/s", "a": "rad/s", "sigma": "rad/s", "n_harmonics": None,
                                 "f_min": "rad/s", "f_max": "rad/s", "seed": None, "amplitude": None}),
    ("Gearbox", "input", {"omega_rotor": "rad/s", "phi_rotor": "rad", "omega_gen": "rad/s", "phi_gen": "rad"}),
    ("Gearbox", "output", {"shaft_torque": "N.m", "shaft_torque_end": "N.m", "shaft_torque_avg": "N.m",
                           "omega_out": "rad/s", "torque_rotor": "N.m", "stage1.F_sp[3]": "N", "stage2.F_rp[1]": "N",
                           "stage3.F_mesh": "N", "shaft1.torque": "N.m", "shaft3.torque": "N.m",
                           "stage1.planet[2].omega": "rad/s", "stage3.driven.omega": "rad/s"}),
    ("Gearbox", "parameter", {"stage1.k0": "N/m^e", "stage1.c0": "N.s/m2",
                              "stage2.lambda": "1/m", "stage3.contact_law": None, "stage2.planet_inertia": "kg.m2",
                              "shaft3.stiffness": "N.m/rad", "shaft2.damping": "N.m.s/rad", "solver.rtol": "1",
                              "solver.max_steps": None, "shaft_torque_mode": None, "extrapolate_inputs": None,
                              "generator_interface": None}),
    ("GeneratorRotor", "input", {"shaft_torque": "N.m", "omega_gearbox": "rad/s"}),
    ("GeneratorRotor", "output", {"omega": "rad/s", "phi": "rad", "generator_torque": "N.m"}),
    ("GeneratorRotor", "parameter", {"inertia": "kg.m2", "counter_torque": "N.m", "initial_speed": "rad/s",
                                     "initial_angle": "rad", "event1.kind": None, "event4.start": "s",
                                     "event4.duration": "s", "event4.factor": "1"}),
])
def test_interface_names_causality_and_units(fmu_path, name, causality, expected):
    found = variables(fmu_path(name))
    for var_name, unit in expected.items():
        assert var_name in found, f"{name} lacks {var_name}"
        v = found[var_name]
        assert v.causality == causality
        assert v.unit == unit
        assert v.description.endswith(f"[{unit or '-'}]")


def test_gearbox_exposes_every_mesh_shaft_and_body_of_the_preset(fmu_path):
    found = variables(fmu_path("Gearbox"))
    outputs = {n for n, v in found.items() if v.causality == "output"}
    forces = {f"stage{k}.F_{m}[{i}]" for k in (1, 2) for m in ("sp", "rp") for i in (1, 2, 3)} | {"stage3.F_mesh"}
    speeds = {f"stage1.{b}.omega" for b in ("sun", "planet[1]", "planet[2]", "planet[3]")}
    speeds |= {f"stage2.{b}.omega" for b in ("carrier", "sun", "planet[1]", "planet[2]", "planet[3]")}
    speeds |= {"stage3.drive.omega", "stage3.driven.omega"}
    main = {"shaft_torque", "shaft_torque_end", "shaft_torque_avg", "omega_out", "torque_rotor", "alpha_out", "alpha_out_max",
            "omega_generator"}
    assert outputs == main | forces | speeds | {"shaft1.torque", "shaft2.torque", "shaft3.torque"}


def test_parameter_defaults_are_the_papers_in_si(fmu_path):
    gearbox = variables(fmu_path("Gearbox"))
    assert float(gearbox["stage1.k0"].start) == pytest.approx(5.0e5 * 1000.0 ** 1.5)  # 5e5 N/mm^1.5
    assert float(gearbox["stage2.c0"].start) == pytest.approx(5.0e4 * 1.0e6)  # 5e4 N s/mm^2
    assert float(gearbox["stage3.lambda"].start) == pytest.approx(600.0e3)  # 600 / mm
    assert float(gearbox["stage1.planet_inertia"].start) == pytest.approx(15.6)  # 1.56e7 kg mm^2
    assert float(gearbox["shaft3.stiffness"].start) == pytest.approx(1.0e5 * 1e-3 * 180.0 / math.pi)
    assert int(gearbox["shaft_torque_mode"].start) == 0  # step average
    generator = variables(fmu_path("GeneratorRotor"))
    assert float(generator["inertia"].start) == pytest.approx(151.0)
    assert float(generator["counter_torque"].start) == pytest.approx(25.4e3)
    wind = variables(fmu_path("WindSource"))
    assert float(wind["omega0"].start) == 16.0 * 2.0 * math.pi / 60.0  # exact: start written with repr
    assert int(wind["amplitude"].start) == 0  # variance-preserving


@pytest.mark.parametrize("name", FMU_NAMES)
def test_model_structure_units_and_capabilities(fmu_path, name):
    root = ET.fromstring(read_member(fmu_path(name)))
    units = {u.get("name"): u for u in root.find("UnitDefinitions")}
    md = read_model_description(str(fmu_path(name)))
    for v in md.modelVariables:
        if v.type == "Real":
            assert v.unit in units
        if v.causality == "output":
            assert v.initial == "calculated" and v.start is None
    assert all(u.dependencies == [] for u in md.outputs)  # no direct feedthrough
    assert {u.variable.name for u in md.initialUnknowns} == {u.variable.name for u in md.outputs}
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    assert md.defaultExperiment.stepSize == "0.001"
    if "N.m" in units:
        assert units["N.m"].find("BaseUnit").attrib == {"kg": "1", "m": "2", "s": "-2"}
    if "N/m^e" in units:
        assert units["N/m^e"].find("BaseUnit") is None  # no integer SI exponents


@pytest.mark.parametrize("name", FMU_NAMES)
def test_archive_carries_its_code_under_private_names(built_fmus, name):
    built = built_fmus[name]
    assert built.package == f"_dtcosim_{name.lower()}_{built.build_id}"
    with zipfile.ZipFile(built.path) as archive:
        files = archive.namelist()
        assert archive.read("resources/slavemodule.txt").decode().strip() == built.slave_module
        slave_sources = [archive.read(f).decode() for f in files
                         if f.startswith(f"resources/{built.package}/slaves/") and f.endswith(".py")]
    assert f"resources/{built.package}/components/model/wind.py" in files
    assert (f"resources/{built.package}/components/model/gearbox_model.py" in files) == (name == "Gearbox")
    assert f"resources/{built.slave_module}.py" in files
    assert not any(f.startswith(("resources/components/", "resources/fmus/")) for f in files)
    assert slave_sources and not any("\nfrom components" in code for code in slave_sources)


def _model(name, preset):
    return kind(name).model(drivetrain_of_preset(preset))


def test_code_hash_is_deterministic_and_names_the_configuration():
    assert code_hash("Gearbox", _model("Gearbox", "table6")) == code_hash("Gearbox", _model("Gearbox", "table6"))
    assert len({code_hash("Gearbox", _model("Gearbox", "table6")), code_hash("Gearbox", _model("Gearbox", "table5")),
                code_hash("WindSource", _model("WindSource", "table6"))}) == 3


def test_slave_imports_are_rewritten_to_the_embedding_package():
    code = "from components.model.wind import X\n    from components import y\nfrom .base import Z\n"
    assert rewrite_slave_imports(code, "m.py") == (
        "from ..components.model.wind import X\n    from ..components import y\nfrom .base import Z\n")
    with pytest.raises(BuildError, match="would not resolve inside an FMU"):
        rewrite_slave_imports("import fmus.build\n", "m.py")


def test_unknown_fmu_or_preset_is_refused(tmp_path):
    with pytest.raises(BuildError, match="unknown FMU 'Gear'"):
        fmu_build.build_fmu("Gear", tmp_path)
    with pytest.raises(BuildError, match="unknown preset 'table9'"):
        fmu_build.build_fmu("Gearbox", tmp_path, preset="table9")


@pytest.mark.slow
def test_cli_build_and_validate(tmp_path, capsys):
    assert dtcosim(["build", "--out", str(tmp_path), "--fmu", "WindSource", "--fmu", "GeneratorRotor"]) == 0
    assert sorted(p.name for p in tmp_path.glob("*.fmu")) == ["GeneratorRotor.fmu", "WindSource.fmu"]
    assert dtcosim(["validate", str(tmp_path)]) == 0
    assert "WindSource.fmu: ok" in capsys.readouterr().out
    # an FMU whose modelDescription lost a unit definition is reported, exit code 1
    broken = tmp_path / "WindSource.fmu"
    xml = read_member(broken).replace(b'<Unit name="rad">', b'<Unit name="radian">')
    rewrite_archive(broken, {"modelDescription.xml": xml})
    assert dtcosim(["validate", str(broken)]) == 1
    assert 'The unit "rad" of variable "phi"' in capsys.readouterr().out
    assert dtcosim(["validate", str(tmp_path / "missing")]) == 1


@pytest.mark.slow
def test_build_script(tmp_path, this_python):
    script = fmu_build.SourceTree.installed().components_dir.parent / "build_fmus.py"
    result = run_python(this_python, str(script), "--out", str(tmp_path), "--fmu", "GeneratorRotor")
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "GeneratorRotor.fmu").is_file()
    assert check_fmu(tmp_path / "GeneratorRotor.fmu") == []


@pytest.mark.slow
@pytest.mark.parametrize("preset", ["table5", "table3"])
def test_single_stage_presets_build_and_run(tmp_path, preset):
    fmu_build.build_all(tmp_path, preset)
    result = load_driver("fmu_loop").run(tmp_path, 0.2, 1.0e-3)
    ratio = cosim_preset(preset).ratio
    omega0 = 16.0 * math.pi / 30.0
    # kinematic start at the preset's ratio; the run completes (the Table 6 generator load is
    # heavy for a single stage, so the speeds themselves are not checked)
    assert result["Gearbox.omega_out"][0] == pytest.approx(ratio * result["WindSource.omega"][0], rel=1e-12)
    assert result["initial_generator_speed"] == pytest.approx(ratio * omega0, rel=0.05)
    assert all(math.isfinite(x) for x in result["Gearbox.shaft_torque"])


def test_documented_variable_tables_match_the_code():
    from fmus.documentation import update

    doc = fmu_build.SourceTree.installed().components_dir.parent / "docs" / "fmus.md"
    if not doc.is_file():
        pytest.skip("docs/fmus.md is not next to the installed package")
    text = doc.read_text(encoding="utf-8")
    assert "<!-- BEGIN GENERATED Gearbox -->" in text
    assert update(text) == text, "run: python -m fmus.documentation --update docs/fmus.md"


@pytest.fixture
def source_copy(tmp_path):
    """A copy of the installed ``components`` and ``fmus/slaves`` to edit: ``(root, SourceTree)``."""
    installed = SourceTree.installed()
    root = tmp_path / "src"
    shutil.copytree(installed.components_dir, root / "components", ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copytree(installed.slaves_dir, root / "fmus" / "slaves", ignore=shutil.ignore_patterns("__pycache__"))
    return root, SourceTree.at(root)


def _build_ids(source):
    return {name: code_hash(name, _model(name, "table6"), source) for name in FMU_NAMES}


def test_analysis_code_does_not_change_a_build_id_the_contact_law_does(source_copy):
    root, source = source_copy
    before = _build_ids(source)
    assert before == _build_ids(SourceTree.installed())
    for rel in ("analysis/fatigue.py", "analysis/modes.py", "analysis/campbell.py", "reference/solver.py"):
        with open(root / "components" / rel, "a") as f:
            f.write("\n# an edit outside the model\nCHANGED = 1\n")
    assert _build_ids(source) == before
    with open(root / "components" / "model" / "contact.py", "a") as f:
        f.write("\nCHANGED = 1\n")
    after = _build_ids(source)
    assert after["Gearbox"] != before["Gearbox"]
    # the wind source's closure also holds contact.py (the parameter description types), so it changes too;
    # what matters: every FMU whose code changed gets a new id, and only those
    assert all(after[n] != before[n] for n in FMU_NAMES if "components.model.contact" in embedded_modules(n, source))


@pytest.mark.parametrize("name", FMU_NAMES)
def test_an_fmu_carries_only_its_slaves_import_closure(built_fmus, name):
    with zipfile.ZipFile(built_fmus[name].path) as archive:
        files = [f for f in archive.namelist() if f.startswith(f"resources/{built_fmus[name].package}/")]
    code = {f.split("/", 2)[2] for f in files if f.endswith(".py")}
    for forbidden in ("fatigue", "modes", "campbell", "modal_verification", "contact_loss", "spectrum", "solver",
                      "cases", "results"):
        assert not any(forbidden in f for f in code), (forbidden, sorted(code))
    assert not any(f.startswith(("components/analysis/", "components/reference/")) for f in code)
    # exactly the closure: one file per module, plus the embedding package's own __init__.py and the runtime guard
    assert len(code) == len(embedded_modules(name)) + 2 and {"__init__.py", GUARD_FILE} <= code


@pytest.mark.parametrize("name", FMU_NAMES)
def test_every_module_an_fmu_carries_has_its_bytecode_which_python_loads_without_compiling(built_fmus, name, tmp_path):
    import importlib.util
    import subprocess
    import sys

    with zipfile.ZipFile(built_fmus[name].path) as archive:
        files = set(archive.namelist())
        sources = sorted(f for f in files if f.startswith("resources/") and f.endswith(".py"))
        pycs = {f: archive.read(importlib.util.cache_from_source(f)) for f in sources}
        archive.extractall(tmp_path)
    assert len(sources) > 20
    assert {f for f in files if f.endswith(".pyc")} == {importlib.util.cache_from_source(f) for f in sources}
    for source, pyc in pycs.items():  # PEP 552: hash-based (bit 0), unchecked (bit 1 clear), this Python's magic
        assert pyc[:4] == importlib.util.MAGIC_NUMBER and int.from_bytes(pyc[4:8], "little") == 0b01, source
    # the slave imported from the extracted folder (new time stamps, as every run extracts it): nothing compiled
    code = (f"import sys, importlib._bootstrap_external as be\nsys.path.insert(0, {str(tmp_path / 'resources')!r})\n"
            "compiled = []\nreal = be.SourceLoader.source_to_code\n"
            "be.SourceLoader.source_to_code = lambda self, data, path, **k: compiled.append(path) or real(self, data, path, **k)\n"
            f"import {built_fmus[name].slave_module}\nprint(compiled)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == "[]"


@pytest.mark.parametrize("name, role, signals", [
    ("WindSource", "wind_source", {"omega": "rotor_speed", "phi": "rotor_angle"}),
    ("GeneratorRotor", "generator", {"omega": "generator_speed", "generator_torque": "generator_torque"}),
    ("Gearbox", "gearbox", {"stage1.F_sp[1]": "contact_force", "stage3.F_mesh": "contact_force",
                            "shaft3.torque": "shaft_torque", "omega_out": "output_speed",
                            "stage1.sun.omega": "body_speed", "shaft_torque": "generator_shaft_torque"}),
])
def test_the_record_declares_role_model_and_signals(built_fmus, name, role, signals):
    path = built_fmus[name].path
    with zipfile.ZipFile(path) as archive:
        record = json.loads(archive.read("resources/dtcosim.json"))
        xml = archive.read("modelDescription.xml").decode()
    assert record["role"] == role and record["fmu"] == name and record["source"] == "preset table6"
    assert '<Tool name="dtcosim">' in xml and f'role="{role}"' in xml and 'record="resources/dtcosim.json"' in xml
    for variable, signal in signals.items():
        assert record["signals"][variable]["signal"] == signal
    assert record["model"] == _model(name, "table6")
    if name == "Gearbox":
        assert record["signals"]["stage1.F_sp[2]"] == {"signal": "contact_force", "stage": "stage1",
                                                       "mesh": "sun_planet", "planet": "2"}
        assert build(record["model"]["drivetrain"]) == drivetrain_of_preset("table6")


def test_an_interrupted_build_leaves_the_previous_fmu_whole_and_nothing_half_written(fmu_path, tmp_path, monkeypatch):
    """pythonfmu wrote straight to <name>.fmu: an interrupted build left a broken archive under the final name
    that later runs never rebuilt (issue 35.3). The build now renames a finished archive into place."""
    out = tmp_path / "fmus"
    out.mkdir()
    shutil.copy(fmu_path("WindSource"), out / "WindSource.fmu")
    before = (out / "WindSource.fmu").read_bytes()

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt  # Ctrl-C while the archive is being completed

    monkeypatch.setattr(fmu_build.model_description, "rewrite_archive", interrupted)
    with pytest.raises(KeyboardInterrupt):
        fmu_build.build_fmu("WindSource", out)
    assert (out / "WindSource.fmu").read_bytes() == before  # the previous FMU, untouched
    assert sorted(p.name for p in out.iterdir()) == ["WindSource.fmu"]  # no partial file or folder left
    monkeypatch.undo()
    built = fmu_build.build_fmu("WindSource", out)
    assert built.path == out / "WindSource.fmu" and check_fmu(built.path) == []
    assert sorted(p.name for p in out.iterdir()) == ["WindSource.fmu"]


def test_the_builds_own_import_of_the_staged_package_compiles_and_writes_no_bytecode(tmp_path, monkeypatch):
    """The staged modules' bytecode is the FMU's, held in memory: pythonfmu's import of the slave compiles none of
    them and writes no __pycache__ into the folder it copies; the FMU still carries each module's bytecode."""
    import importlib.machinery

    from pythonfmu import FmuBuilder

    compiled, seen = [], {}
    real_compile = importlib.machinery.SourceFileLoader.source_to_code
    monkeypatch.setattr(importlib.machinery.SourceFileLoader, "source_to_code",
                        lambda self, data, path, **kw: compiled.append(str(path)) or real_compile(self, data, path, **kw))
    real = FmuBuilder.build_FMU

    def build_fmu(script, **options):
        package = options["project_files"][0]
        out = real(script, **options)
        seen["imported"] = f"{package.name}.slaves.generator_rotor" in sys.modules
        seen["compiled"] = [path for path in compiled if path.startswith(str(script.parent))]
        seen["bytecode"] = sorted(p.name for p in script.parent.rglob("*.pyc"))
        return out

    monkeypatch.setattr(FmuBuilder, "build_FMU", staticmethod(build_fmu))
    built = fmu_build.build_fmu("GeneratorRotor", tmp_path)
    assert seen == {"imported": True, "compiled": [], "bytecode": []}
    with zipfile.ZipFile(built.path) as archive:
        names = set(archive.namelist())
    assert f"resources/{built.package}/slaves/__pycache__/generator_rotor.{sys.implementation.cache_tag}.pyc" in names
    assert f"resources/{built.slave_module}.py" in names and \
        f"resources/__pycache__/{built.slave_module}.{sys.implementation.cache_tag}.pyc" in names


def test_bytecode_of_a_source_two_fmus_embed_is_compiled_once_and_names_each_file(tmp_path):
    """fmus.bytecode.unchecked_pyc: the code py_compile writes (same header and code), under each member's name."""
    import importlib.util
    import marshal
    import py_compile

    source = b"def outer():\n    def inner():\n        return 1\n    return inner\n\nclass K:\n    def m(self):\n        pass\n"
    (tmp_path / "mod.py").write_bytes(source)
    py_compile.compile(str(tmp_path / "mod.py"), cfile=str(tmp_path / "mod.pyc"), dfile="resources/a/mod.py",
                       doraise=True, invalidation_mode=py_compile.PycInvalidationMode.UNCHECKED_HASH)
    expected = (tmp_path / "mod.pyc").read_bytes()
    bytecode.compiled.cache_clear()
    bytecode.unchecked_pyc.cache_clear()
    first = bytecode.unchecked_pyc(source, "resources/a/mod.py")
    second = bytecode.unchecked_pyc(source, "resources/b/mod.py")
    assert bytecode.compiled.cache_info().misses == 1 and bytecode.compiled.cache_info().hits == 1
    assert first[:16] == expected[:16] == second[:16] and expected[8:16] == importlib.util.source_hash(source)
    assert marshal.loads(first[16:]) == marshal.loads(expected[16:])

    def filenames(code):
        return {code.co_filename}.union(*(filenames(c) for c in code.co_consts if hasattr(c, "co_filename")))

    assert filenames(marshal.loads(first[16:])) == {"resources/a/mod.py"}
    assert filenames(marshal.loads(second[16:])) == {"resources/b/mod.py"}
    outer = {}
    exec(marshal.loads(second[16:]), outer)
    assert outer["outer"]().__code__.co_filename == "resources/b/mod.py" and outer["outer"]()() == 1


def test_members_are_appended_without_touching_the_others_and_never_twice(tmp_path):
    from fmus.model_description import add_members

    fmu = tmp_path / "x.fmu"
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("modelDescription.xml", b"<fmiModelDescription/>" * 100)
    before = fmu.read_bytes()
    add_members(fmu, {"documentation/cross-check/X_ref.csv": b'"time"\n0.0\n'})
    after = fmu.read_bytes()
    # the first member's local header and compressed data are where they were, byte for byte
    with zipfile.ZipFile(fmu) as archive:
        first = archive.getinfo("modelDescription.xml")
        end = first.header_offset + 30 + len(first.filename) + len(first.extra) + first.compress_size
        assert after[:end] == before[:end]
        assert archive.read("documentation/cross-check/X_ref.csv") == b'"time"\n0.0\n' and archive.testzip() is None
    with pytest.raises(ValueError, match="already has documentation/cross-check/X_ref.csv"):
        add_members(fmu, {"documentation/cross-check/X_ref.csv": b""})
