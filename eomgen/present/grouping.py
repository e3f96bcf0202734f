"""Textbook grouping: M, C and g of a :class:`~eomgen.symbolic.textbook.TextbookDerivation` as
every document prints them (the LaTeX document, the handout, the notebook, the Jupyter display):
entries of M grouped by body mass, those of g by trigonometric factor
(:mod:`eomgen.present.readability`).
"""

from __future__ import annotations

import sympy as sp

from ..symbolic.textbook import TextbookDerivation
from . import readability as rd


def body_masses(book: TextbookDerivation) -> list[sp.Symbol]:
    """The masses of ``book``'s bodies that are symbols, in body order: what entries of M are
    grouped by (numeric masses are not factors a reader follows)."""
    return [b.mass for b in book.bodies if isinstance(b.mass, sp.Symbol)]


def grouped_matrices(book: TextbookDerivation) -> dict:
    """M, C and g of ``book``: entries of M grouped by body mass, those of g by trigonometric
    factor (sums built unevaluated, so their order is kept; print them with
    :func:`eomgen.present.display.expression_latex`)."""
    masses = body_masses(book)
    angles = list(book.q)
    return {"M": book.M.applyfunc(lambda e: rd.mass_grouped(e, masses)),
            "C": book.C,
            "g": book.g.applyfunc(lambda e: rd.trig_grouped(e, angles))}
