"""Build the dtcosim FMUs (those of :mod:`fmus.registry`) with pythonfmu.

Each FMU is self-contained and collision-free:

* its ``resources/`` hold a package ``_dtcosim_<fmu>_<hash>`` with exactly the
  code its slave imports (the import closure of the slave module,
  :func:`fmus.source_closure.import_closure`: the slave modules under
  ``slaves/`` and the ``components`` modules they need, in their subpackages),
  where ``<hash>`` is a hash of that code, the FMU name, the model it is
  built from and the pythonfmu version. The slave modules' ``from components...`` imports are
  rewritten to package-relative imports, so the FMU never imports an installed
  ``components`` (or another FMU's copy); analysis and reference code is not
  embedded and does not change an FMU's build id;
* the pythonfmu entry script is ``_dtcosim_<fmu>_<hash>_slave.py`` (pythonfmu
  imports it by file stem, and module names are shared by every FMU in a
  host process): it only subclasses the slave with the build id;
* ``resources/dtcosim.json`` is the FMU's record (:mod:`fmus.slaves.record`):
  the parameter set it is built from (a drivetrain preset's structure and
  defaults; wind and generator parameter sets), its declared role, the
  signals of its outputs and the bounds of its parameters (probed from the
  slave's own validation, :func:`fmus.parameter_ranges.parameter_bounds`; also
  written as FMI ``min``/``max``). The slave builds its interface from that record at
  instantiation, and hosts read it instead of guessing what the FMU is.

Two FMUs built from different code therefore run their own code in one
process, and an FMU runs where numpy and scipy exist but dtcosim does not.
After pythonfmu has written the archive, ``modelDescription.xml`` gets units,
InitialUnknowns and output dependencies (:mod:`fmus.model_description`) and is
checked with ``fmpy.validation``.
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import importlib
import importlib.util
import json
import os
import re
import shutil
import sys
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

import pythonfmu
from pythonfmu import FmuBuilder

import components
from components.errors import DtcosimError, os_error_text
from components.model.drivetrain import Drivetrain
from components.model.wind import WindParameters

from . import binary, bytecode, model_description, registry, runtime_files
from .build_lock import build_lock, building_prefix
from .build_pool import build_each
from .parameter_ranges import parameter_bounds
from .records import full_record
from .slaves import base as slave_base
from .slaves.record import RECORD_FILE
from .source_closure import SourceModule, import_closure

#: Bump when the layout of the generated FMUs changes.
BUILD_FORMAT = 2

#: the FMUs built from a preset (or a drivetrain) alone; a TimeSeriesSource is built from a load record
#: (:func:`build_fmu` with ``model`` and ``resources``, :mod:`orchestrator.provision.series_fmus`)
PRESET_FMU_NAMES = registry.names_built_from(registry.PRESET)

_COMPONENTS_IMPORT = re.compile(r"^(\s*)from components((?:\.\w+)*) import ", re.MULTILINE)
_FORBIDDEN_IMPORT = re.compile(r"^\s*(?:from|import)\s+(?:components|fmus|orchestrator)\b", re.MULTILINE)
_MIN_PYTHONFMU = (0, 7, 0)


class BuildError(DtcosimError):
    """An FMU could not be built or the built FMU is not valid."""


def _kind(name: str) -> registry.FmuKind:
    """The registry's entry of FMU ``name``; an unknown name is a :class:`BuildError` naming the known ones."""
    try:
        return registry.kind(name)
    except registry.UnknownFmu as exc:
        raise BuildError(str(exc)) from None


@dataclass(frozen=True)
class SourceTree:
    """Where the code copied into the FMUs comes from.

    Attributes
    ----------
    components_dir : Path
        The ``components`` package.
    slaves_dir : Path
        The ``fmus/slaves`` package.
    """

    components_dir: Path
    slaves_dir: Path

    @classmethod
    def installed(cls) -> "SourceTree":
        """The packages this module was imported with."""
        return cls(Path(components.__file__).parent, Path(slave_base.__file__).parent)

    @classmethod
    def at(cls, root: Path) -> "SourceTree":
        """A checkout (or copy) with ``components/`` and ``fmus/slaves/`` under ``root``."""
        root = Path(root)
        return cls(root / "components", root / "fmus" / "slaves")


@dataclass(frozen=True)
class BuiltFmu:
    """Result of one build.

    Attributes
    ----------
    name : str
        Model name (``WindSource``, ``Gearbox`` or ``GeneratorRotor``).
    path : Path
        The ``.fmu`` file.
    build_id : str
        Hash of the embedded code and configuration.
    package : str
        Name of the embedded package (``_dtcosim_<fmu>_<hash>``).
    slave_module : str
        Name of the pythonfmu entry module.
    """

    name: str
    path: Path
    build_id: str
    package: str
    slave_module: str


def _check_pythonfmu() -> None:
    version = tuple(int(p) for p in re.findall(r"\d+", pythonfmu.__version__)[:3])
    if version < _MIN_PYTHONFMU:
        raise BuildError(
            f"pythonfmu {pythonfmu.__version__} is too old: >= {'.'.join(map(str, _MIN_PYTHONFMU))} is needed "
            "(its C wrapper finds the slave class through the class hierarchy)"
        )


def embedded_modules(name: str, source: SourceTree | None = None) -> dict[str, SourceModule]:
    """The modules FMU ``name`` carries: the import closure of its slave module.

    Returns
    -------
    dict of str -> SourceModule
        By dotted name: ``fmus.slaves.*`` (the slave, the base slave and what they import)
        and the ``components`` modules and packages they need.
    """
    source = source or SourceTree.installed()
    packages = {"components": source.components_dir, "fmus": source.slaves_dir.parent}
    found = import_closure([f"fmus.slaves.{_kind(name).slave_module}"], packages)
    return {k: m for k, m in found.items() if k.startswith(("components", "fmus.slaves"))}


def _embedded_files(name: str, source: SourceTree) -> list[tuple[str, Path]]:
    """(path inside the embedded package, source file) of every module FMU ``name`` carries.

    Found by parsing the modules (:func:`embedded_modules`), once per FMU and state of the sources
    (:func:`sources_stamp`) in a process: a build needs it three times.
    """
    return list(_embedded_files_of(name, source, sources_stamp(source)))


@functools.lru_cache(maxsize=64)
def _embedded_files_of(name: str, source: SourceTree, stamp: str) -> tuple[tuple[str, Path], ...]:
    out = []
    for mod in embedded_modules(name, source).values():
        if mod.name.startswith("fmus.slaves"):
            rel = "slaves/" + mod.path.relative_to(source.slaves_dir).as_posix()
        else:
            rel = "components/" + mod.path.relative_to(source.components_dir).as_posix()
        out.append((rel, mod.path))
    out.append((runtime_files.GUARD_FILE, runtime_files.GUARD_SOURCE))  # the requirement check the FMU runs first
    return tuple(out)


def build_config(name: str, model: dict) -> dict:
    """Configuration that, together with the code, determines an FMU: its name and record ``model``."""
    return {"format": BUILD_FORMAT, "fmu": name, "model": model, "pythonfmu": pythonfmu.__version__,
            "dtcosim": components.__version__, "binary": binary.source_digest()}


def stamped_files(source: SourceTree | None = None) -> list[Path]:
    """Every file :func:`code_hash` may read, for any FMU: the ``.py`` files of ``components`` and ``fmus/slaves``,
    the FMU binary's C sources and the runtime guard."""
    source = source or SourceTree.installed()
    files = [path for folder in (source.components_dir, source.slaves_dir) for path in sorted(Path(folder).rglob("*.py"))
             if "__pycache__" not in path.parts]
    files += [binary.NATIVE_DIR / name for name in (*binary.SOURCES, binary.HEADER)]
    return files + [runtime_files.GUARD_SOURCE]


def sources_stamp(source: SourceTree | None = None) -> str:
    """A stamp of everything :func:`code_hash` reads, by file stats: equal stamps, equal hashes.

    The path, size and modification time of each of :func:`stamped_files`, and the versions
    in :func:`build_config`. Nothing is read or hashed: a check that remembers its verdict
    under this stamp (and the FMU file's stats) repeats it in milliseconds
    (:mod:`orchestrator.provision.staleness`).
    """
    entries = [f"{BUILD_FORMAT} {pythonfmu.__version__} {components.__version__}"]
    for path in stamped_files(source):
        st = path.stat()
        entries.append(f"{path} {st.st_size} {st.st_mtime_ns}")
    return hashlib.sha256("\n".join(entries).encode()).hexdigest()[:16]


def code_hash(name: str, model: dict, source: SourceTree | None = None) -> str:
    """12-hex-digit hash of the code embedded in FMU ``name`` and of the model it is built from."""
    source = source or SourceTree.installed()
    digest = hashlib.sha256(json.dumps(build_config(name, model), sort_keys=True).encode())
    for rel, path in _embedded_files(name, source):
        digest.update(rel.encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()[:12]


def rewrite_slave_imports(code: str, module: str) -> str:
    """Make a slave module's ``from components...`` imports relative to the embedding package."""
    code = _COMPONENTS_IMPORT.sub(r"\1from ..components\2 import ", code)
    leftover = _FORBIDDEN_IMPORT.search(code)
    if leftover:
        raise BuildError(f"slave module {module}: import {leftover.group(0).strip()!r} would not resolve inside an FMU")
    return code


def _entry_script(name: str, package: str, module: str, origin: str, build_id: str) -> str:
    return (
        f'"""pythonfmu entry module of the dtcosim {name} FMU (generated by fmus.build; do not edit).\n\n'
        f"Built from {origin}, build {build_id}: the slave and physics code are in the package\n"
        f'{package} next to this file, the model in {RECORD_FILE}.\n"""\n\n'
        f"from pythonfmu.enums import Fmi2Status as _Fmi2Status\n\n"
        f"from {package} import runtime_guard as _runtime_guard\n\n\n"
        f"def _import_slave():\n    from {package}.slaves.{module} import {name}\n\n    return {name}\n\n\n"
        "# A missing requirement (numpy, ...) or a too old Python becomes an ImportError naming it, also\n"
        "# written to stderr; pythonfmu logs it (fmi2Fatal) and fmi2Instantiate returns NULL.\n"
        f'_{name} = _runtime_guard.load_slave("{name}", __file__, _import_slave)\n\n'
        "# pythonfmu's C wrapper (0.7) executes this file again for every new instance, in this\n"
        "# module's namespace, and then releases a reference to that namespace it never took.\n"
        "# Without a reference added by each execution the namespace is freed while the module\n"
        "# still uses it and the host crashes later (reproduced). Costs one list entry per instance.\n"
        '_namespace_refs = globals().setdefault("_namespace_refs", [])\n'
        "_namespace_refs.append(globals())\n\n\n"
        f"class {name}(_{name}):\n"
        f'    """dtcosim {name} ({origin}, build {build_id})."""\n\n'
        f'    build_id = "{build_id}"\n'
        f'    version = "{components.__version__}+{build_id}"\n'
        f'    description = _{name}.description + " ({origin}, build {build_id})"\n\n'
        "    def __init__(self, **kwargs):\n"
        "        super().__init__(**kwargs)\n"
        "        for message in _runtime_guard.warnings():  # versions outside the tested ranges\n"
        "            self.log(message, _Fmi2Status.warning)\n"
    )


def stage(name: str, model: dict, origin: str, staging_dir: Path,
          source: SourceTree | None = None) -> tuple[Path, Path, str, dict[str, bytes]]:
    """Write the entry script, the embedded package and the record of FMU ``name`` into ``staging_dir``.

    The record written here has no signals yet (they come from the slave's
    interface, known once pythonfmu has imported it; :func:`build_fmu` completes it).

    Returns
    -------
    script, package_dir : Path
    build_id : str
    pycs : dict of str -> bytes
        The bytecode of each staged module (the entry script's too) by the path of its ``__pycache__`` file, as
        the FMU will carry it (:mod:`fmus.bytecode`), kept in memory: the build's own import of the staged
        package (pythonfmu reads the slave class) takes it from there (:func:`fmus.bytecode.imported_from`) and
        compiles nothing, and no bytecode file is written for pythonfmu to copy.
    """
    kind = _kind(name)
    source = source or SourceTree.installed()
    build_id = code_hash(name, model, source)
    package = f"_dtcosim_{name.lower()}_{build_id}"
    package_dir = Path(staging_dir) / package
    pycs = {}

    def write(target: Path, data: bytes) -> None:
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data)
        member = f"resources/{target.relative_to(staging_dir).as_posix()}"
        pycs[importlib.util.cache_from_source(str(target))] = bytecode.unchecked_pyc(data, member)

    for rel, path in _embedded_files(name, source):
        write(package_dir / rel, _staged_source(rel, path))
    _bundle_compiled_kernels(package_dir)
    info = {"format": BUILD_FORMAT, "fmu": name, "origin": origin, "build_id": build_id}
    write(package_dir / "__init__.py",
          f'"""Code embedded in the dtcosim {name} FMU (generated by fmus.build)."""\n\nBUILD_INFO = {info!r}\n'.encode())
    script = Path(staging_dir) / f"{package}_slave.py"
    write(script, _entry_script(name, package, kind.slave_module, origin, build_id).encode())
    (Path(staging_dir) / RECORD_FILE).write_text(json.dumps(full_record(name, "", model, origin), indent=1),
                                                 encoding="utf-8")
    return script, package_dir, build_id, pycs


def _staged_source(rel: str, path: Path) -> bytes:
    """The content of embedded module ``rel`` (from ``path``): a slave module's imports made package-relative."""
    code = path.read_text(encoding="utf-8")
    if rel.startswith("slaves/"):
        code = rewrite_slave_imports(code, path.name)
    return code.encode("utf-8")


def _bundle_compiled_kernels(package_dir: Path) -> list[Path]:
    """Copy the kernels compiled ahead of time for the staged kernel sources beside them; returns the copies.

    Only modules built on this machine from byte-identical sources (their names are keyed by
    the sources) are carried: with them the FMU steps compiled code without numba on any host
    with the same platform, Python and numpy (:mod:`components.compile.aot`); the build id stays
    the code's, the modules being derived from it.
    """
    import components
    from components.compile.aot import BUNDLE_FOLDER, AotKernel
    from components.compile.sources import KernelSource
    from components.model.kernel import AHEAD_OF_TIME

    project = Path(components.__file__).resolve().parent.parent
    copies = []
    for installed in AHEAD_OF_TIME:
        staged = package_dir / installed.entry.relative_to(project)
        if not staged.is_file():
            continue
        kernel = AotKernel.of(KernelSource(installed.name, staged))
        built = kernel.file()
        if built.is_file():
            target = kernel.file(staged.parent / BUNDLE_FOLDER)
            target.parent.mkdir(exist_ok=True)
            shutil.copyfile(built, target)
            copies.append(target)
    return copies


def _forget_modules(prefixes: Sequence[str], path_entries: Sequence[str]) -> None:
    """Drop the staged modules from this process (the FMU must import its own copy)."""
    for key in [k for k in sys.modules if any(k == p or k.startswith(p + ".") for p in prefixes)]:
        del sys.modules[key]
    for entry in path_entries:
        while entry in sys.path:
            sys.path.remove(entry)
    importlib.invalidate_caches()


def drivetrain_of_preset(preset: str) -> Drivetrain:
    """The co-simulation drivetrain of a preset name (:func:`fmus.registry.drivetrain_of_preset`).

    Raises
    ------
    BuildError
        Naming the presets there are.
    """
    try:
        return registry.drivetrain_of_preset(preset)
    except ValueError as exc:
        raise BuildError(str(exc)) from None


def build_fmu(name: str, out_dir: Path | str, preset: str = "table6", source: SourceTree | None = None,
              validate: bool = True, *, drivetrain: Drivetrain | None = None, origin: str | None = None,
              rotor_speed_rad_s: float | None = None, model: dict | None = None,
              resources: dict[str, Path] | None = None, report: Callable[[str], None] | None = None) -> BuiltFmu:
    """Build one FMU into ``out_dir`` (``<out_dir>/<name>.fmu``).

    Parameters
    ----------
    name : str
        A model name of :data:`fmus.registry.KINDS`.
    out_dir : path
        Output directory (created if missing).
    preset : {"table6", "table5", "table3"}
        Drivetrain preset: structure and parameter defaults (unless ``drivetrain`` is given).
    source : SourceTree, optional
        Code to embed (default: the installed ``components`` and ``fmus.slaves``).
    validate : bool
        Check the result with ``fmpy.validation`` and raise :class:`BuildError` on problems.
    drivetrain : Drivetrain, optional
        The co-simulation drivetrain (with generator and output shaft) to build from instead of a preset.
    origin : str, optional
        What the drivetrain was made from, for the record (default ``"preset <preset>"``).
    rotor_speed_rad_s : float, optional
        Rotor speed of the operating point [rad/s]: the start values of the Gearbox's inputs, the
        generator's initial speed and the WindSource's omega0 (default: the paper's 16 rpm).
    model : dict, optional
        The FMU's record model to build from instead of the one of the drivetrain (a TimeSeriesSource's
        ``{"series": ...}``); it must name the content of ``resources`` (a hash) so that the build id does.
    resources : dict of str -> Path, optional
        Extra files packed into the FMU's ``resources/`` (name inside -> file), e.g. ``series.npz``.
    report : callable(str), optional
        Told when another process is building into ``out_dir`` and this build waits for it
        (:func:`fmus.build_lock.build_lock`).
    """
    _check_pythonfmu()
    kind = _kind(name)
    source = source or SourceTree.installed()
    if drivetrain is None:
        drivetrain = drivetrain_of_preset(preset)
        origin = origin or f"preset {preset}"
    origin = origin or "a drivetrain given to fmus.build"
    wind = None if rotor_speed_rad_s is None else WindParameters(mean_speed_rad_s=rotor_speed_rad_s)
    if model is None:
        model = kind.model(drivetrain, wind)
    out_dir = Path(out_dir)
    # written, completed and checked under a temporary name in the same folder, then renamed: an interrupted
    # build leaves no FMU under the final name; one build at a time per folder (fmus.build_lock)
    final = out_dir / f"{name}.fmu"
    try:
        with build_lock(out_dir, report), tempfile.TemporaryDirectory(prefix=building_prefix(name),
                                                                      dir=out_dir) as part:
            built = _build_archive(name, kind, model, origin, source, Path(part), resources, validate)
            os.replace(built.path, final)
    except OSError as exc:  # a full disk: the error names no file, or one the build copied from
        raise BuildError(f"{final} not built: {os_error_text(exc)} (the build writes into {out_dir} and the temporary "
                         f"folder {tempfile.gettempdir()})") from None
    return dataclasses.replace(built, path=final)


def _build_archive(name, kind, model, origin, source, part_dir: Path, resources, validate) -> BuiltFmu:
    """The whole FMU ``<part_dir>/<name>.fmu`` (see :func:`build_fmu`)."""
    with tempfile.TemporaryDirectory(prefix="dtcosim_fmu_") as tmp:
        script, package_dir, build_id, pycs = stage(name, model, origin, Path(tmp), source)
        package = package_dir.name
        runtime = runtime_files.write(Path(tmp), name, origin, model, build_id, components.__version__,
                                      [path for _, path in _embedded_files(name, source)])
        importlib.invalidate_caches()
        try:
            with bytecode.imported_from(pycs, [package, script.stem]):
                fmu_path = Path(FmuBuilder.build_FMU(script, dest=part_dir / f"{name}.fmu",
                                                     project_files=[package_dir, Path(tmp) / RECORD_FILE,
                                                                    runtime.requirements_file,
                                                                    *_staged_resources(Path(tmp), resources)],
                                                     documentation_folder=runtime.documentation_dir,
                                                     canGetAndSetFMUstate=True, canSerializeFMUstate=True))
                variables = getattr(sys.modules[script.stem], name).interface(model)
        finally:
            _forget_modules([package, script.stem], [str(script.parent)])
    bounds = parameter_bounds(name, model)
    record = full_record(name, kind.role, model, origin, variables, bounds)
    xml = model_description.finalize(
        model_description.read_member(fmu_path), variables, build_id,
        f"dtcosim {components.__version__} with PythonFMU {pythonfmu.__version__}",
        role=kind.role, record_file=f"resources/{RECORD_FILE}", bounds=bounds,
    )
    xml = runtime_files.describe(xml, runtime.requirements)
    members = {model_description.MODEL_DESCRIPTION: xml,
               f"resources/{RECORD_FILE}": json.dumps(record, indent=1).encode()}
    try:
        members.update(binary.native_members(name, name))
    except binary.NativeBuildError as exc:  # the FMU keeps pythonfmu's binary: C hosts must preload libpython
        warnings.warn(f"{name}.fmu keeps pythonfmu's linux64 binary, which C hosts must preload libpython for: {exc}",
                      stacklevel=2)
    members.update(bytecode.members(fmu_path))
    model_description.rewrite_archive(fmu_path, members)
    if validate:
        from .validation import check_fmu

        problems = check_fmu(fmu_path)
        if problems:
            raise BuildError(f"{fmu_path} is not valid:\n  " + "\n  ".join(problems))
    case = kind.cross_check_case(model)
    if case is not None:
        _add_cross_check(name, fmu_path, case)
    return BuiltFmu(name, fmu_path, build_id, package, script.stem)


def _add_cross_check(name: str, fmu_path: Path, case) -> None:
    """Run the finished FMU stand-alone and pack its cross-check files (:mod:`fmus.cross_check`) into it."""
    from .cross_check import reference_members

    try:
        members = reference_members(fmu_path, case)
    except Exception as exc:  # the FMU's own run failed: the build must not ship it
        raise BuildError(f"{name}.fmu: its stand-alone cross-check run failed: {type(exc).__name__}: {exc}") from None
    model_description.add_members(fmu_path, members)  # the archive is still under its temporary name


def _staged_resources(tmp: Path, resources: dict[str, Path] | None) -> list[Path]:
    """Copies of the extra resource files under their names inside the FMU (pythonfmu packs by file name)."""
    out = []
    for inside, path in (resources or {}).items():
        target = tmp / "extra_resources" / inside
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(Path(path).read_bytes())
        out.append(target)
    return out


def build_all(out_dir: Path | str, preset: str = "table6", source: SourceTree | None = None,
              names: Sequence[str] = PRESET_FMU_NAMES, validate: bool = True,
              report: Callable[[str], None] | None = None,
              after_each: Callable[[Path], object] | None = None) -> list[BuiltFmu]:
    """Build the FMUs ``names`` (default: every FMU of a preset) into ``out_dir`` (``report``: see :func:`build_fmu`),
    by :func:`build_several`."""
    return build_several(names, out_dir, preset=preset, source=source, validate=validate, report=report,
                         after_each=after_each)


def build_several(names: Sequence[str], out_dir: Path | str, report: Callable[[str], None] | None = None,
                  after_each: Callable[[Path], object] | None = None, **options) -> list[BuiltFmu]:
    """``[build_fmu(name, out_dir, report=report, **options) for name in names]``, on two processes where that is
    safe (:func:`fmus.build_pool.build_each`), holding the folder's build lock for both.

    ``after_each(path)``: called with each FMU once it is in place, by the process that built it (e.g. to unpack it
    for the run that asked for it, off that run's path when a forked builder built it); what it returns is ignored.

    The FMU binary, where it is not compiled yet (the first build of a machine), compiles in a process of its own
    from the start (:func:`fmus.binary.start_compile`), beside :func:`prepare_builds` and the builds' first steps;
    begun at the fork, it took ~0.45 s on the path of a first run's builds.
    """
    names = list(names)
    if not names:
        return []
    with build_lock(out_dir, report):
        compiling = binary.start_compile()
        try:
            prepare_builds(names, options.get("source"))
            build = functools.partial(build_fmu, out_dir=out_dir, report=report, **options)
            built = build_each(build if after_each is None else functools.partial(_build_then, build, after_each),
                               names)
        except BaseException:
            if compiling is not None:
                compiling.stop()
            raise
        if compiling is not None:
            compiling.finish()
        return built


def _build_then(build: Callable[[str], BuiltFmu], after: Callable[[Path], object], name: str) -> BuiltFmu:
    built = build(name)
    after(built.path)
    return built


def prepare_builds(names: Sequence[str], source: SourceTree | None = None) -> None:
    """Do what every build of FMUs ``names`` starts with once, so that a forked builder (:mod:`fmus.build_pool`)
    starts with it done: import what a build imports when first needed (fmpy's simulation and validation, the XML
    parsers fmpy and pythonfmu use, the slaves), find the modules each FMU embeds and compile their sources (the
    FMUs share most of them), and look up the installed distributions their requirements name (each reads a file
    list once per process)."""
    import sysconfig
    import xml.dom.expatbuilder  # noqa: F401 - pythonfmu's model description (minidom.parseString)

    from fmpy import simulation, validation  # noqa: F401 - the cross-check run, the archive check
    from lxml import etree  # noqa: F401 - fmpy.read_model_description's parser

    sysconfig.get_config_vars()  # the FMU binary's members (fmus.binary) read them

    from . import cross_check, validation as fmu_validation  # noqa: F401

    source = source or SourceTree.installed()
    for name in names:
        _kind(name).slave_class()
        embedded = _embedded_files(name, source)
        for rel, path in embedded:
            bytecode.compiled(_staged_source(rel, path))
        runtime_files.requirements(name, [path for _, path in embedded])
