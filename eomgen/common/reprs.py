"""Rich display in notebooks, registered rather than imported: the bottom of the display path.

Plain reprs are here too: :func:`field_repr` (a dataclass's repr, its numbers as the shortest
text that reads back to the same double: ``mass=0.629769``, not SymPy's seventeen digits
``0.62976900000000002``) and :func:`names` (a short list of names), for the short reprs of the
big objects a user meets (a model, derived dynamics, a scene's report).

Data classes (:class:`eomgen.model.RobotModel`, :class:`eomgen.dynamics.Dynamics`) keep the
``_repr_html_`` / ``_repr_latex_`` methods Jupyter looks for, and each asks this registry for the
renderer of its kind (``"model"``, ``"dynamics"``). The renderers live with the presentation
code (:mod:`eomgen.present.display`), which registers them when it is imported (``import eomgen`` does,
cheaply: display imports what it renders with only when it renders). So the data classes depend
on nothing above them, and a kind with no renderer registered falls back to the plain ``repr``.

>>> register("thing", "text/html", lambda t: "<b>thing</b>")
>>> render("thing", object(), "text/html")
'<b>thing</b>'
>>> render("nothing", object(), "text/html") is None
True
>>> del RENDERERS[("thing", "text/html")]
"""

from __future__ import annotations

import dataclasses
import enum
import functools
from typing import Callable, Iterable

#: (kind, MIME type) → renderer returning the text of that MIME type.
RENDERERS: dict[tuple[str, str], Callable[[object], str]] = {}


def register(kind: str, mime: str, renderer: Callable[[object], str]) -> None:
    """Render objects of ``kind`` (``"model"``, ``"dynamics"``) as ``mime`` with ``renderer``."""
    RENDERERS[(kind, mime)] = renderer


def render(kind: str, obj: object, mime: str) -> str | None:
    """``obj`` as ``mime`` by the renderer registered for ``kind``; None when none is
    registered (Jupyter then shows the plain ``repr``)."""
    renderer = RENDERERS.get((kind, mime))
    return None if renderer is None else renderer(obj)


@functools.cache
def _printer():
    """SymPy's ``str`` printer with each Float as the shortest text that reads back to its
    double (``repr(float)``): the model keeps floats at 17 digits, which print with noise.
    Made on first use: importing this module does not import SymPy."""
    from sympy.printing.str import StrPrinter

    class ShortFloats(StrPrinter):
        def _print_Float(self, expr) -> str:
            return repr(float(expr))

    return ShortFloats()


def value_repr(value) -> str:
    """``repr(value)``, with SymPy numbers and expressions printed by :func:`_printer`,
    through tuples and lists (a nested dataclass by its own repr).

    >>> import sympy as sp
    >>> value_repr((sp.Float(0.629769, 17), sp.Float(0.5, 17) * sp.Symbol("l1"), 2))
    '(0.629769, 0.5*l1, 2)'
    """
    if type(value).__module__.startswith("sympy"):
        return _printer().doprint(value)
    if isinstance(value, tuple) and not hasattr(value, "_fields"):
        inner = ", ".join(value_repr(v) for v in value)
        return f"({inner},)" if len(value) == 1 else f"({inner})"
    if isinstance(value, list):
        return "[" + ", ".join(value_repr(v) for v in value) + "]"
    if isinstance(value, enum.Enum):
        return f"{type(value).__name__}.{value.name}"
    return repr(value)


def field_repr(obj) -> str:
    """A dataclass's repr as :func:`dataclasses.dataclass` writes it (the fields with
    ``repr=True``), each value by :func:`value_repr`. Assign it as ``__repr__``."""
    fields = ", ".join(f"{f.name}={value_repr(getattr(obj, f.name))}"
                       for f in dataclasses.fields(obj) if f.repr)
    return f"{type(obj).__name__}({fields})"


def names(items: Iterable[str], most: int = 6) -> str:
    """``"a, b, c"``; past ``most``, the first ones and how many more.

    >>> names(["q1", "q2"]), names([f"q{k}" for k in range(1, 10)], most=3)
    ('q1, q2', 'q1, q2, q3, … (6 more)')
    """
    items = list(items)
    more = f", … ({len(items) - most} more)" if len(items) > most else ""
    return ", ".join(items[:most]) + more
