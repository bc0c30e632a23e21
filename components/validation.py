"""Small validators used by the frozen parameter dataclasses.

Each validator raises :class:`~components.errors.ParameterError` naming the
parameter, its value and what was expected. NaN and infinity are rejected by
every numeric check.

Magnitudes
----------
A physical parameter may not exceed :data:`MAX_MAGNITUDE` (1e30) in size, and
a positive one may not be below :data:`MIN_POSITIVE` (1e-30): within these,
products, squares and inverses of a few parameters stay finite (``1 / 5e-324``
or ``1e308 * r^2`` would not, and the model would produce infinities instead of
an error). Integers are FMI Integers (32 bits: :data:`INT32_MIN` to
:data:`INT32_MAX`) unless a smaller limit is given.

Bounds
------
Every validator with a simple numeric range attaches it to the error it raises
as a :class:`Bounds` (``error.bounds``): inclusive minimum and maximum, whether
the value must be an integer, and the expectation text. The FMU build probes
the slaves for these and publishes them (FMI ``min``/``max`` and the FMU's
record), so a host checks a value with :meth:`Bounds.check` and gets the same
message as the FMU gives.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np

from .errors import ParameterError

#: largest magnitude of a physical parameter
MAX_MAGNITUDE = 1.0e30
#: smallest positive physical parameter
MIN_POSITIVE = 1.0e-30
#: range of an FMI 2 Integer (a C int)
INT32_MIN, INT32_MAX = -(2**31), 2**31 - 1


@dataclass(frozen=True)
class Bounds:
    """An inclusive numeric range and the expectation a value outside it is told.

    Attributes
    ----------
    minimum, maximum : float or int
    integer : bool
        The value must be a whole number.
    expected : str
        The expectation of the error message (``"> 0 (within [1e-30, 1e+30])"``).
    """

    minimum: float
    maximum: float
    integer: bool
    expected: str

    def check(self, name: str, value: Any) -> float | int:
        """``value`` if it is inside, else :class:`ParameterError` naming ``name`` with :attr:`expected`."""
        if self.integer:
            ok = is_number(value) and (isinstance(value, int) or (math.isfinite(value) and value == int(value)))
        else:
            ok = is_number(value)
        if not ok or not self.minimum <= value <= self.maximum:
            raise ParameterError(name, value, self.expected, self)
        return value

    def as_dict(self) -> dict[str, Any]:
        """Plain JSON data (for an FMU's record)."""
        return {"min": self.minimum, "max": self.maximum, "integer": self.integer, "expected": self.expected}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> "Bounds":
        """The inverse of :meth:`as_dict`."""
        integer = bool(data["integer"])
        conv = int if integer else float
        return cls(conv(data["min"]), conv(data["max"]), integer, str(data["expected"]))


def _g(x: float) -> str:
    return f"{x:g}"


POSITIVE = Bounds(MIN_POSITIVE, MAX_MAGNITUDE, False, f"> 0 (within [{_g(MIN_POSITIVE)}, {_g(MAX_MAGNITUDE)}])")
NON_NEGATIVE = Bounds(0.0, MAX_MAGNITUDE, False, f">= 0 (at most {_g(MAX_MAGNITUDE)})")
FINITE = Bounds(-MAX_MAGNITUDE, MAX_MAGNITUDE, False, f"a finite real number (magnitude at most {_g(MAX_MAGNITUDE)})")


def integer_bounds(minimum: int, maximum: int = INT32_MAX) -> Bounds:
    """The bounds of an integer parameter (an FMI Integer unless ``maximum`` is smaller)."""
    if maximum >= INT32_MAX:
        text = f"an integer >= {minimum} (at most {INT32_MAX}, an FMI Integer)"
    else:
        text = f"an integer within [{minimum}, {maximum}]"
    return Bounds(int(minimum), int(min(maximum, INT32_MAX)), True, text)


def choice_bounds(choices: tuple[str, ...], text: str) -> Bounds:
    """The bounds of an Integer code ``0 ... len(choices) - 1`` that encodes a choice."""
    return Bounds(0, len(choices) - 1, True, text)


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


def _within(name: str, value: Any, x: float, bounds: Bounds) -> float:
    if not bounds.minimum <= x <= bounds.maximum:
        raise ParameterError(name, value, bounds.expected, bounds)
    return x


def finite(name: str, value: Any) -> float:
    """Return ``value`` as float; reject non-numbers, NaN, infinity and magnitudes above :data:`MAX_MAGNITUDE`."""
    return _within(name, value, _as_real(name, value), FINITE)


def positive(name: str, value: Any) -> float:
    """Return ``value`` as float; require ``value > 0`` (within [:data:`MIN_POSITIVE`, :data:`MAX_MAGNITUDE`])."""
    return _within(name, value, _as_real(name, value), POSITIVE)


def non_negative(name: str, value: Any) -> float:
    """Return ``value`` as float; require ``0 <= value <= MAX_MAGNITUDE``."""
    return _within(name, value, _as_real(name, value), NON_NEGATIVE)


def in_range(name: str, value: Any, low: float, high: float) -> float:
    """Return ``value`` as float; require ``low <= value <= high``."""
    return _within(name, value, _as_real(name, value), Bounds(float(low), float(high), False,
                                                              f"within [{low:g}, {high:g}]"))


def integer_at_least(name: str, value: Any, minimum: int, maximum: int = INT32_MAX) -> int:
    """Return ``value`` as int; require an integer within [``minimum``, ``maximum``] (default: an FMI Integer).

    The check comes before anything is allocated from the value (sizes such as
    a number of harmonics are capped by ``maximum``).
    """
    bounds = integer_bounds(minimum, maximum)
    if isinstance(value, bool):
        raise ParameterError(name, value, bounds.expected, bounds)
    if isinstance(value, float):
        if not math.isfinite(value) or value != int(value):
            raise ParameterError(name, value, bounds.expected, bounds)
    elif not isinstance(value, int) and not hasattr(value, "__index__"):
        raise ParameterError(name, value, bounds.expected, bounds)
    n = int(value)
    if not bounds.minimum <= n <= bounds.maximum:
        raise ParameterError(name, value, bounds.expected, bounds)
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
