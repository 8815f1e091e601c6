"""Markdown tables of bench rows, as docs/bench.md holds them."""


def markdown_table(rows, columns, note="", digits=4, formats=None) -> str:
    """``rows`` (dicts) as a Markdown table of ``columns``: a cell by its column's format
    in ``formats`` (``str.format`` strings), else a float to ``digits`` significant
    digits, else as it is; empty for None (or a column the row lacks). Then ``note``
    (what the columns hold), if any."""
    formats = formats or {}

    def cell(column, value):
        if value is None:
            return ""
        if column in formats:
            return formats[column].format(value)
        return f"{value:.{digits}g}" if isinstance(value, float) else str(value)

    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(cell(c, row.get(c)) for c in columns) + " |" for row in rows]
    return "\n".join(lines) + ("\n\n" + note + "\n" if note else "\n")
