"""Rich display in notebooks, registered rather than imported: the bottom of the display path.

Data classes (:class:`eomgen.model.RobotModel`, :class:`eomgen.dynamics.Dynamics`) keep the
``_repr_html_`` / ``_repr_latex_`` methods Jupyter looks for, and each asks this registry for the
renderer of its kind (``"model"``, ``"dynamics"``). The renderers live with the presentation
code (:mod:`eomgen.display`), which registers them when it is imported (``import eomgen`` does,
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

from typing import Callable

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
