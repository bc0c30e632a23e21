"""One module per source version, whichever copy of the sources asks (components.model.shared_module)."""

from __future__ import annotations

import sys

import pytest

from components.model.shared_module import load_shared, shared_name

KERNEL = "from .helper import SCALE\n\ndef scaled(x):\n    return SCALE * x\n"


def _copy(root, package: str, scale: int, kernel: str = KERNEL):
    """A package ``package`` under ``root`` holding ``kernel.py`` and ``helper.py`` (SCALE = scale)."""
    folder = root / package
    folder.mkdir(parents=True)
    (folder / "__init__.py").write_text("")
    (folder / "kernel.py").write_text(kernel)
    (folder / "helper.py").write_text(f"SCALE = {scale}\n")
    return folder / "kernel.py"


@pytest.fixture
def packages(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    before = set(sys.modules)
    yield tmp_path
    for name in set(sys.modules) - before:  # the test's packages and shared modules
        del sys.modules[name]


def test_copies_with_the_same_sources_share_one_module(packages):
    first = _copy(packages, "build_a", 3)
    second = _copy(packages, "build_b", 3)
    a = load_shared(first, "build_a", ("helper.py",))
    b = load_shared(second, "build_b", ("helper.py",))
    assert a is b and a.scaled(2) == 6
    assert a.__name__ == shared_name(second, ("helper.py",)) and a.__name__.startswith("_dtcosim_kernel_")
    assert a.__file__ == str(first)  # executed once, from the copy that asked first


def test_a_different_dependency_is_another_module(packages):
    a = load_shared(_copy(packages, "build_a", 3), "build_a", ("helper.py",))
    c = load_shared(_copy(packages, "build_c", 5), "build_c", ("helper.py",))
    assert a is not c and (a.scaled(1), c.scaled(1)) == (3, 5)


def test_a_module_that_fails_to_execute_is_not_kept(packages):
    path = _copy(packages, "build_a", 3, kernel="import module_that_does_not_exist\n")
    with pytest.raises(ModuleNotFoundError, match="module_that_does_not_exist"):
        load_shared(path, "build_a", ("helper.py",))
    assert shared_name(path, ("helper.py",)) not in sys.modules


def test_try_load_shared_says_why_and_tries_once(packages):
    from components.model.shared_module import try_load_shared

    marker = packages / "attempts.txt"
    path = _copy(packages, "build_a", 3, kernel=f"open({str(marker)!r}, 'a').write('x')\nimport no_such_module\n")
    first = try_load_shared(path, "build_a", ("helper.py",))
    assert first == (None, "ModuleNotFoundError: No module named 'no_such_module'")
    assert try_load_shared(path, "build_a", ("helper.py",)) == first and marker.read_text() == "x"
    good = _copy(packages, "build_b", 3)
    module, reason = try_load_shared(good, "build_b", ("helper.py",))
    assert reason is None and module.scaled(2) == 6
