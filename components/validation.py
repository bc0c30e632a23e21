"""Small validators used by the frozen parameter dataclasses.

Each validator raises :class:`~components.errors.ParameterError` naming the
parameter, its value and what was expected. NaN and infinity are rejected by
every numeric check.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .errors import ParameterError


def is_number(value: Any) -> bool:
    """True for an ``int`` or ``float`` that is not a ``bool`` (a TOML/JSON number)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _as_real(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) and not hasattr(value, "__float__"):
        raise ParameterError(name, value, "a real number")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ParameterError(name, value, "a real number") from None
    if not math.isfinite(x):
        raise ParameterError(name, value, "a finite real number")
    return x


def finite(name: str, value: Any) -> float:
    """Return ``value`` as float; reject non-numbers, NaN and infinity."""
    return _as_real(name, value)


def positive(name: str, value: Any) -> float:
    """Return ``value`` as float; require ``value > 0``."""
    x = _as_real(name, value)
    if not x > 0.0:
        raise ParameterError(name, value, "> 0")
    return x


def non_negative(name: str, value: Any) -> float:
    """Return ``value`` as float; require ``value >= 0``."""
    x = _as_real(name, value)
    if not x >= 0.0:
        raise ParameterError(name, value, ">= 0")
    return x


def in_range(name: str, value: Any, low: float, high: float) -> float:
    """Return ``value`` as float; require ``low <= value <= high``."""
    x = _as_real(name, value)
    if not low <= x <= high:
        raise ParameterError(name, value, f"within [{low:g}, {high:g}]")
    return x


def integer_at_least(name: str, value: Any, minimum: int) -> int:
    """Return ``value`` as int; require an integer ``>= minimum``."""
    if isinstance(value, bool):
        raise ParameterError(name, value, f"an integer >= {minimum}")
    if isinstance(value, float):
        if not math.isfinite(value) or value != int(value):
            raise ParameterError(name, value, f"an integer >= {minimum}")
    elif not isinstance(value, int) and not hasattr(value, "__index__"):
        raise ParameterError(name, value, f"an integer >= {minimum}")
    n = int(value)
    if n < minimum:
        raise ParameterError(name, value, f"an integer >= {minimum}")
    return n


def one_of(name: str, value: Any, choices: tuple[str, ...]) -> str:
    """Require ``value`` to be one of ``choices``."""
    if value not in choices:
        raise ParameterError(name, value, "one of " + ", ".join(repr(c) for c in choices))
    return value


def set_fields(obj: Any, **values: Any) -> None:
    """Assign normalised values to a frozen dataclass inside ``__post_init__``."""
    for key, val in values.items():
        object.__setattr__(obj, key, val)


def finite_series(name: str, values: Any, min_samples: int, dtype: type | None = float) -> np.ndarray:
    """``values`` as a 1-D array of at least ``min_samples`` finite samples.

    ``dtype`` float by default; None keeps the input's type (e.g. a complex modal coordinate).

    Raises
    ------
    ParameterError
        Naming ``name`` and the array's shape, or ``"non-finite samples"``.
    """
    y = np.asarray(values, dtype=dtype)
    if y.ndim != 1 or y.size < min_samples:
        raise ParameterError(name, y.shape, f"a 1-D series of at least {min_samples} samples")
    if not np.all(np.isfinite(y)):
        raise ParameterError(name, "non-finite samples", "finite values")
    return y
