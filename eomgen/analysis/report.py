"""Tables (Markdown, CSV), the Pareto front, and the Matplotlib set-up shared by the analyses."""

from __future__ import annotations

import csv
import io
from typing import Sequence


def markdown_table(headers: Sequence[str], rows: Sequence[Sequence[object]],
                   align: str | None = None) -> str:
    """A GitHub Markdown table; ``align`` is one letter per column (``l``, ``r``), default
    left for the first column and right for the others.

    >>> print(markdown_table(["a", "b"], [["x", 1]]))
    | a | b |
    | --- | ---: |
    | x | 1 |
    """
    align = align or "l" + "r" * (len(headers) - 1)
    rule = ["---:" if a == "r" else "---" for a in align]

    def line(cells):
        return "| " + " | ".join(str(c).replace("|", "\\|") for c in cells) + " |"

    return "\n".join([line(headers), line(rule)] + [line(r) for r in rows])


def csv_text(headers: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """CSV text (``\\n`` line ends) of ``rows`` under ``headers``."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(headers)
    writer.writerows(rows)
    return buffer.getvalue()


def pareto_front(points: Sequence[tuple[float, float]], tie: float = 1.0) -> list[int]:
    """Indices of the points no other point beats, both coordinates (time, error) minimised.

    Point a beats point b when ``a.x <= b.x`` and ``a.y <= tie * b.y``, and a is better in one
    of them: ``a.x < b.x`` or ``tie * a.y < b.y``. With ``tie = 2``, errors within a factor of
    two count as equal (the largest of a few dozen rounding errors varies that much from one
    sample to the next), so a route that is slower and "more accurate" by 4.3e-16 against
    4.5e-16 is not on the front. Sorted by the first coordinate.

    >>> pareto_front([(1, 5), (2, 1), (3, 3), (1, 6)])
    [0, 1]
    >>> pareto_front([(1, 4.5e-16), (9, 4.3e-16)], tie=2)
    [0]
    """
    def beats(a, b):
        return (a[0] <= b[0] and a[1] <= tie * b[1]) and (a[0] < b[0] or tie * a[1] < b[1])

    front = [i for i, p in enumerate(points)
             if not any(beats(other, p) for j, other in enumerate(points) if j != i)]
    return sorted(front, key=lambda i: points[i])


def pyplot():
    """``matplotlib.pyplot`` with the non-interactive Agg backend (files only, no display).

    Raises
    ------
    ImportError
        With the install hint, when Matplotlib is missing.
    """
    try:  # optional dependency (the analysis extra): imported when a plot is made
        import matplotlib
    except ImportError as exc:  # pragma: no cover - the analysis extra installs it
        raise ImportError("plots need Matplotlib: pip install 'eomgen[analysis]'") from exc
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt  # after choosing the Agg backend above

    return plt


def fmt(x: float, digits: int = 2) -> str:
    """A float in short scientific notation (``1.2e-15``); ``-`` for None, ``inf``, ``nan`` as
    such; 0 as ``0``."""
    if x is None:
        return "-"
    if x != x:
        return "nan"
    if x in (float("inf"), float("-inf")):
        return "inf" if x > 0 else "-inf"
    if x == 0:
        return "0"
    return f"{x:.{digits - 1}e}"
