"""Read the tables of an HTML page (the FMUs' documentation) with the standard library's parser."""

from __future__ import annotations

from html.parser import HTMLParser


class _Tables(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.tables: dict[str, list[list[str]]] = {}
        self.ids: list[str] = []
        self._table: list[list[str]] | None = None
        self._cell: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if "id" in attrs:
            self.ids.append(attrs["id"])
        if tag == "table":
            self._table = self.tables.setdefault(attrs.get("id", f"table{len(self.tables)}"), [])
        elif tag == "tr" and self._table is not None:
            self._table.append([])
        elif tag in ("td", "th") and self._table is not None:
            self._cell = []

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self._table[-1].append("".join(self._cell).strip())
            self._cell = None
        elif tag == "table":
            self._table = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)


def tables(text: str) -> tuple[dict[str, list[dict[str, str]]], list[str]]:
    """``({table id: [row as {header: cell}]}, element ids)`` of an HTML page."""
    parser = _Tables()
    parser.feed(text)
    parser.close()
    out = {}
    for key, rows in parser.tables.items():
        header, *body = rows
        out[key] = [dict(zip(header, row)) for row in body]
    return out, parser.ids
