"""A read-only mapping that, unlike :class:`types.MappingProxyType`, pickles.

Scenarios, studies and FMU interfaces are frozen dataclasses holding mappings;
they cross process boundaries (Dask workers, ``multiprocessing``), so their
mappings must survive the standard :mod:`pickle`.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any, TypeVar

K = TypeVar("K")
V = TypeVar("V")


class FrozenMap(Mapping[K, V]):
    """Immutable view of a private copy of ``data``; equal to any mapping with the same items.

    Parameters
    ----------
    data : mapping or iterable of (key, value) pairs
    """

    __slots__ = ("_data",)

    def __init__(self, data: Mapping[K, V] | Any = ()) -> None:
        object.__setattr__(self, "_data", dict(data))

    def __getitem__(self, key: K) -> V:
        return self._data[key]

    def __iter__(self) -> Iterator[K]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"{type(self).__name__} is read-only")

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._data!r})"

    def __reduce__(self):
        return (type(self), (self._data,))
