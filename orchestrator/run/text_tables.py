"""Plain-text tables for an 80-column terminal.

:func:`fit_table` lays out a header and rows of cells: the first column (a
variable name) is left-aligned, the others right-aligned, two spaces apart, and
the whole line never wider than :data:`TERMINAL_COLUMNS`. A name too long for
the room the value columns leave goes on a line of its own, its values on the
next line, so nothing is cut and columns never run together.
"""

from __future__ import annotations

from typing import Sequence

TERMINAL_COLUMNS = 80
GAP = 2


def fit_table(header: Sequence[str], rows: Sequence[Sequence[str]], indent: int = 2,
              width: int = TERMINAL_COLUMNS) -> list[str]:
    """The lines of a table whose every line fits ``width`` columns (see the module docstring).

    Parameters
    ----------
    header : sequence of str
        Column titles, the name column first.
    rows : sequence of sequence of str
        Formatted cells, as many as titles.
    indent : int
        Spaces before each line.
    """
    n = len(header)
    values = [max(len(header[j]), *(len(r[j]) for r in rows)) if rows else len(header[j]) for j in range(1, n)]
    room = width - indent - sum(w + GAP for w in values)
    longest = max([len(header[0]), *(len(r[0]) for r in rows)])
    name_width = max(min(longest, room), 0)
    pad = " " * indent

    def line(name: str, cells: Sequence[str]) -> str:
        return (pad + f"{name:<{name_width}}" + "".join(" " * GAP + f"{c:>{w}}" for c, w in zip(cells, values))).rstrip()

    out = [line(header[0] if len(header[0]) <= name_width else "", header[1:])]
    for row in rows:
        if len(row[0]) > name_width:
            out.append(pad + row[0])
            out.append(line("", row[1:]))
        else:
            out.append(line(row[0], row[1:]))
    return out


def number(value, fmt: str = ".5g") -> str:
    """A cell for a number, ``-`` for None (a non-finite value in ``summary.json``)."""
    return "-" if value is None else format(value, fmt)
