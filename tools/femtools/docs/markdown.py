"""The Markdown every generated table is written in: the table itself and its numbers."""


def ms(x):
    """A time in milliseconds, to about four significant digits."""
    return f"{x:.3f}" if x < 10 else f"{x:.2f}" if x < 100 else f"{x:.1f}"


def ratio(a, b):
    """a over b as a speedup, x1.23 ("-" without a b)."""
    return f"x{a / b:.2f}" if b > 0 else "-"


def table(header, rows, align=None):
    """A Markdown table ending in a newline; the first column left-aligned, the rest right
    unless align says otherwise."""
    align = align or ["---"] + ["---:"] * (len(header) - 1)
    lines = ["| " + " | ".join(header) + " |", "| " + " | ".join(align) + " |"]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"
