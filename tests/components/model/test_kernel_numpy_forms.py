"""Every numpy-written kernel function computes what its loop computes, to the bit (the sign of zero included).

A kernel module's ``COMPILED`` maps a function written with numpy calls (what the interpreted kernel
runs) to the loop numba compiles in its place (:mod:`components.compile.jit`). The loops are plain
Python too, so both run here without numba, on the arrays of the packaged gearboxes and on random
ones with zeros of both signs, empty rows and non-finite entries where a function can meet them. A
case exists for every entry of ``COMPILED`` in the modules of the gearbox and monolithic kernels (the last test
checks that).
"""

from __future__ import annotations

import copy
import importlib

import numpy as np
import pytest

from components.model.assembly import Assembly
from components.model.gearbox_model import GearboxModel
from components.model.kernel import GEARBOX, MONOLITHIC
from components.model.presets import cosim_preset
from components.model.sparse import column_sparsity
from orchestrator.inputs.drivetrain_file import load_drivetrain_file, packaged_drivetrains

#: the modules of the gearbox's and the monolithic reference's kernels (the drivetrain's equations)
KERNEL_MODULES = sorted({path.stem for source in (GEARBOX, MONOLITHIC) for path in source.files})


def _module(name: str):
    return importlib.import_module(f"components.model.kernel.{name}")


def _assemblies() -> dict[str, Assembly]:
    table6 = cosim_preset("table6")
    lateral = load_drivetrain_file(packaged_drivetrains()["paper-table6-lateral"]).cosim_drivetrain()
    return {"table6": Assembly(table6, cut_at_generator=True),
            "table6-tvs-impact": Assembly(table6.with_meshes(stiffness_variation=0.3, law="impact"),
                                          cut_at_generator=True),
            "lateral": Assembly(lateral, cut_at_generator=True)}


ASSEMBLIES = _assemblies()


def _signed_zeros(rng, x: np.ndarray, share: float = 0.2) -> np.ndarray:
    """``x`` with a share of its entries replaced by +0.0 and -0.0."""
    x = np.array(x, dtype=float)
    hit = rng.random(x.shape) < share
    x[hit] = np.where(rng.random(x.shape) < 0.5, 0.0, -0.0)[hit]
    return x


def _sparse(rng, rows: int, cols: int, density: float = 0.35) -> np.ndarray:
    return _signed_zeros(rng, rng.normal(size=(rows, cols)) * (rng.random((rows, cols)) < density))


def _regular(rng, n: int) -> np.ndarray:
    """A sparse, well-conditioned matrix (a factorisation's ``G``), its zeros of both signs."""
    g = np.eye(n) * rng.uniform(1.0, 4.0, n) + _sparse(rng, n, n, 0.25)
    return g


def _deflections(rng, a: Assembly) -> np.ndarray:
    """Deflections around the backlash (both flanks, inside the gap, deep) and their rates, rows (2, n_mesh)."""
    half = a.law.table[:, 4]
    d = half * rng.choice([-1.0, 1.0], half.size) + rng.normal(0.0, 3e-5, half.size)
    d[::4] = rng.uniform(-0.5, 0.5, d[::4].size) * half[::4]
    d[1::5] *= 40.0
    return np.array([d, rng.normal(0.0, 5e-3, half.size)])


def _pattern(index: np.ndarray, rows: int) -> np.ndarray:
    """A dense matrix that is random on a row pattern (``index``, padded with -1) and -0.0 elsewhere."""
    rng = np.random.default_rng(7)
    w = np.full((index.shape[0], rows), -0.0)
    for i, cols in enumerate(index):
        for j in cols[cols >= 0].astype(int):
            w[i, j] = rng.normal()
    return w


# ------------------------------------------------------------------ cases: name -> arguments (fresh per call)
def _linalg_cases(rng, a: Assembly, nonfinite: bool) -> dict:
    n, m = a.n_dof, a.n_mesh
    x = _signed_zeros(rng, rng.normal(size=n))
    if nonfinite:
        x[rng.integers(n)] = rng.choice([np.inf, -np.inf, np.nan])
    w = _sparse(rng, n, n)
    ci, cv = column_sparsity(w)
    jac = _pattern(a.jacobian_index, n)
    lu = _regular(rng, n)
    piv = np.zeros(n)
    _module("linalg")._lu_factor_loop(lu, piv)
    lower, upper = np.zeros((n, n)), np.zeros((n, n))
    _module("linalg")._lu_pattern_loop(lu, lower, upper)
    return {
        "copy": lambda: (x.copy(), np.empty(n)),
        "matvec": lambda: (w, x, np.empty(n)),
        "vecmat": lambda: (x, w, np.empty(n)),
        "vecmat_add": lambda: (x, w, rng.normal(size=n)),
        "matmul": lambda: (w, _sparse(rng, n, 3), np.empty((n, 3))),
        "vecmat_sum": lambda: (x, w, rng.normal(size=2), _sparse(rng, 2, n), _signed_zeros(rng, np.zeros(3)),
                               _sparse(rng, 3, n), np.empty(n)),
        "axpy": lambda: (-0.7, x, _signed_zeros(rng, rng.normal(size=n))),
        "axpy2": lambda: (0.3, x, -1.1, rng.normal(size=n), _signed_zeros(rng, rng.normal(size=n))),
        "dot": lambda: (x, _signed_zeros(rng, rng.normal(size=n))),
        "subtract": lambda: (x, _signed_zeros(rng, rng.normal(size=n)), np.empty(n)),
        "negate": lambda: (x.copy(),),
        "sparse_vecmat": lambda: (x, ci, cv, np.empty(ci.shape[0])),
        "matvec_pattern": lambda: (jac, a.jacobian_index, x, np.empty(n)),
        "invert": lambda: (_regular(rng, n), np.empty((n, n))),
        "lu_factor": lambda: (_regular(rng, n), np.empty(n)),
        "lu_pattern": lambda: (lu, np.empty((n, n)), np.empty((n, n))),
        "lu_solve": lambda: (lu, piv, lower, upper, x, np.empty(n)),
    }


def _model_cases(rng, a: Assembly, nonfinite: bool) -> dict:
    n, m = a.n_dof, a.n_mesh
    table, phasing = a.law.table, a.phasing_table
    defl = _deflections(rng, a)
    factor = rng.uniform(0.8, 1.2, m)
    y = _signed_zeros(rng, rng.normal(0.0, 1e-4, 2 * n))
    if nonfinite:
        y[rng.integers(2 * n)] = rng.choice([np.inf, np.nan])
    integrator = _module("integrator")
    ginv, pivots = np.empty((n, n)), np.empty((2 * n + 1, n))
    dq = _pattern(a.jacobian_index, n) * 1e6
    dv = _pattern(a.jacobian_index, n) * 1e2
    hd = 1e-4 * integrator.D
    integrator._factor_loop(hd, dq, dv, ginv, pivots)
    ports = a.ports.size
    stks_port = a.STkS_port[:, 0] if ports else np.zeros(n)
    stcs_port = a.STcS_port[:, 0] if ports else np.zeros(n)
    curve = rng.normal(size=4)
    vectors = lambda k: [_signed_zeros(rng, rng.normal(size=2 * n)) for _ in range(k)]  # noqa: E731
    return {
        "mesh_forces": lambda: (defl, factor, table, np.empty(m), np.empty(m)),
        "forces": lambda: (defl, factor, table, np.empty(m)),
        "force_slopes": lambda: (defl, factor, table, np.empty(m), np.empty(m)),
        "stiffness_force_rates": lambda: (defl, factor, table, rng.normal(size=m), 1.7, np.empty(m)),
        "deflections": lambda: (y, n, a.nz_index, a.nz_value, a.port_deflection,
                                _signed_zeros(rng, a.mesh_offset + rng.normal(0.0, 1e-5, m)), 1e-3, -2e-2,
                                np.empty((2, m))),
        "assemble_jacobian": lambda: (_signed_zeros(rng, rng.normal(0, 1e9, m)), rng.normal(0, 1e3, m), a.nz_index,
                                      a.nz_value, a.port_deflection, a.cos_alpha, a.STkS, a.STcS, stks_port, stcs_port,
                                      a.inv_inertia, np.empty((n, n)), np.empty((n, n)), np.empty((2, n))),
        "factor": lambda: (hd, dq, dv, np.empty((n, n)), np.empty((2 * n + 1, n))),
        "solve": lambda: (ginv, pivots, dq, a.jacobian_index, hd, y, np.empty(2 * n), np.empty(n)),
        "solve_lower": lambda: (ginv, pivots, hd, y[:n], np.empty(2 * n)),
        "twist_and_rate": lambda: (np.concatenate((a.S[-1], np.zeros(n))), y, n, -1.3, curve, 2.5e-3),
        "stage": lambda: (*vectors(3), 0.7e-3, np.empty(2 * n)),
        "third_rhs": lambda: (*vectors(5), np.empty(2 * n)),
        "error_norm": lambda: (*vectors(2), y, *vectors(2), n, 3e-9, 3e-6, 3e-5),  # y: NaN or inf when nonfinite
        "basis_terms": lambda: (_signed_zeros(rng, rng.normal(size=(4, 2 * n))), 0.3, -1e-3, 2e-6, np.empty(2 * n)),
        "motion_terms": lambda: (rng.normal(size=(2, n)), a.kinematic_ratio, 0.2, -3.0, 40.0, np.empty(n)),
        "stiffness_factors": lambda: (rng.normal(0.0, 30.0), phasing, np.empty(m), np.empty(m)),
        "stiffness_factors_many": lambda: (np.concatenate(([0.0, -0.0], rng.normal(0.0, 30.0, 50))), phasing,
                                           np.empty((52, m)), np.empty((52, m))),
        "views": lambda: _buffer_of(rng, GearboxModel(a.drivetrain, kernel="numpy")),
    }


def _buffer_of(rng, model: GearboxModel) -> tuple:
    """A buffer of ``model``'s layout (random contents), its offsets and sizes: the kernel step's tables."""
    return rng.normal(size=model._buffer.size), model._offsets, model._dims


MODULE_OF = {name: module for module in KERNEL_MODULES for name in getattr(_module(module), "COMPILED", {})}


def _cases(rng, a: Assembly, nonfinite: bool) -> dict:
    return {**_linalg_cases(rng, a, nonfinite), **_model_cases(rng, a, nonfinite)}


def _same(got, want) -> bool:
    """Equal to the bit: values, NaNs where NaN, and the sign of every non-NaN entry (zeros included)."""
    got, want = np.asarray(got), np.asarray(want)
    if np.iscomplexobj(want):
        return _same(got.real, want.real) and _same(got.imag, want.imag)
    got, want = got.astype(float), want.astype(float)
    if got.shape != want.shape or not np.array_equal(got, want, equal_nan=True):
        return False
    numbers = ~np.isnan(want)
    return bool(np.array_equal(np.signbit(got[numbers]), np.signbit(want[numbers])))


def _run(function, arguments) -> tuple:
    """``function`` on a deep copy of ``arguments``: its result and the arguments after the call."""
    args = copy.deepcopy(arguments)
    with np.errstate(invalid="ignore", over="ignore"):
        result = function(*args)
    return result, args


@pytest.mark.parametrize("nonfinite", [False, True], ids=["finite", "nonfinite"])
@pytest.mark.parametrize("assembly", list(ASSEMBLIES))
@pytest.mark.parametrize("name", sorted(MODULE_OF))
def test_the_numpy_form_computes_what_the_loop_computes(name, assembly, nonfinite):
    module = _module(MODULE_OF[name])
    numpy_form, loop = getattr(module, name), module.COMPILED[name]
    rng = np.random.default_rng(abs(hash((name, assembly))) % 2**32)
    for _ in range(6):
        arguments = _cases(rng, ASSEMBLIES[assembly], nonfinite)[name]()
        result, after = _run(numpy_form, arguments)
        expected, expected_after = _run(loop, arguments)
        results = result if isinstance(result, tuple) else (result,)
        expects = expected if isinstance(expected, tuple) else (expected,)
        assert all(_same(r, e) for r, e in zip(results, expects)), (name, results, expects)
        for k, (got, want) in enumerate(zip(after, expected_after)):
            if isinstance(want, np.ndarray):
                assert _same(got, want), (name, k, got, want)


@pytest.mark.parametrize("name, size", [("invert", (3, 3)), ("lu_factor", (3,))])
def test_a_zero_pivot_raises_as_the_compiled_loop_does(name, size):
    """numba's compiled loop raises ZeroDivisionError on a zero pivot (Python's float semantics); so does the numpy
    form (the loop run by Python on numpy scalars would give inf)."""
    with pytest.raises(ZeroDivisionError, match="division by zero"):
        getattr(_module("linalg"), name)(np.zeros((3, 3)), np.empty(size))


def test_every_loop_of_the_kernel_has_a_case():
    """A ``COMPILED`` entry added to a module of the gearbox or monolithic kernel is compared here (its case above)."""
    cases = set(_cases(np.random.default_rng(0), ASSEMBLIES["table6"], False))
    assert set(MODULE_OF) <= cases, sorted(set(MODULE_OF) - cases)
    assert {"linalg", "contact", "dynamics", "integrator", "stiffness", "monolithic"} <= set(MODULE_OF.values())


def test_the_interpreted_views_are_kept_per_buffer():
    """The interpreted step keeps a buffer's views by the identity of the buffer and its tables: never another's."""
    step = _module("step")
    models = [GearboxModel(cosim_preset("table6"), kernel="numpy") for _ in range(step.KEPT_VIEWS + 2)]
    tables = [(g._buffer, g._lay, g._sizes) for g in models]
    kept = step.views(*tables[0])
    assert step.views(*tables[0]) is kept
    assert np.shares_memory(kept.state, tables[0][0])
    others = [step.views(*t) for t in tables[1:]]
    assert all(not np.shares_memory(k.state, tables[0][0]) for k in others)
    again = step.views(*tables[0])  # dropped when more were asked for, made anew from the same buffer
    assert again is not kept and all(_same(a, b) for a, b in zip(again[:-2], kept[:-2]))
    copy_of_tables = (tables[0][0], list(tables[0][1]), list(tables[0][2]))
    assert step.views(*copy_of_tables) is not again  # equal tables in other objects: views made for them


def test_the_contact_rows_are_kept_per_table():
    """The numpy form reads a contact table's rows once per table object: an equal table in another object, or the
    same one after more tables than kept were read, is read anew."""
    contact = _module("contact")
    tables = [np.full((3, 9), float(i)) for i in range(contact.KEPT_TABLES + 1)]
    rows = contact.table_rows(tables[0])
    assert rows == tables[0].tolist() and contact.table_rows(tables[0]) is rows
    equal = tables[0].copy()
    assert contact.table_rows(equal) is not rows and contact.table_rows(equal) == rows
    assert [contact.table_rows(t) for t in tables[1:]] == [t.tolist() for t in tables[1:]]
    again = contact.table_rows(tables[0])  # dropped when more were asked for, read anew
    assert again is not rows and again == rows


def test_the_extended_mesh_patterns_are_kept_per_table():
    """deflections' numpy form extends a mesh pattern once per set of table objects: other objects (equal or not), or
    the same after more patterns than kept were extended, are extended anew."""
    dynamics = _module("dynamics")
    a = ASSEMBLIES["table6"]
    n, m = a.n_dof, a.n_mesh
    tables = tuple(np.array(t) for t in (a.nz_index, a.nz_value, a.port_deflection, a.mesh_offset))
    kept = dynamics.extended_pattern(n, *tables)
    assert dynamics.extended_pattern(n, *tables) is kept
    assert kept[0].shape == (2, m, a.nz_index.shape[1] + 2) and kept[0].dtype == np.intp
    offset = np.full(m, 7.0)
    other = dynamics.extended_pattern(n, *tables[:3], offset)
    assert other is not kept and _same(other[1][:, -1], offset)
    for k in range(dynamics.KEPT_PATTERNS):
        dynamics.extended_pattern(n, tables[0].copy(), *tables[1:])
    again = dynamics.extended_pattern(n, *tables)  # dropped when more were asked for, made anew
    assert again is not kept and all(_same(x, y) for x, y in zip(again, kept))


def test_models_stepped_in_turns_step_as_alone():
    """Interpreted gearboxes stepped in turns (more than the views kept) compute what each computes alone."""
    from components.model.kernel.step import KEPT_VIEWS

    drivetrains = [cosim_preset("table6"), cosim_preset("table6").with_meshes(law="impact")] * (KEPT_VIEWS // 2 + 1)

    def run(models, steps):
        for model in models:
            model.initialize(0.0, 1.6, 0.0, 1.6 * model.ratio, 0.0)
        out = [[] for _ in models]
        for k in range(steps):
            for model, rows in zip(models, out):
                model.step(k * 2e-3, 2e-3, 1.6, 1.6 * k * 2e-3, 1.6 * model.ratio, 1.6 * model.ratio * k * 2e-3)
                rows.append(model.output_vector())
        return [np.array(rows) for rows in out]

    together = run([GearboxModel(dt, kernel="numpy") for dt in drivetrains], 4)
    for dt, rows in zip(drivetrains[:2], together[:2]):
        alone = run([GearboxModel(dt, kernel="numpy")], 4)[0]
        assert _same(rows, alone)
