"""Notation for people: how eomgen writes a derivation in LaTeX, shared by the LaTeX document,
the handout, the notebook and the Jupyter display.

* :class:`LatexConfig`: the document options (template, sizes, digits) and the bounds of a
  teaching-sized model; :func:`teaching_sized` and :func:`textbook_for` apply those bounds;
* :func:`printing`: the :class:`~eomgen.present.printer.DerivationLatexPrinter` of one
  derivation (joint variables ``q_{1}``, ``\\dot{q}_{1}``, compact ``s_{1}``, ``c_{12}``,
  parameters that would read like the document's own quantities as upright text), with the helpers
  :func:`vector`, :func:`rpy` and :func:`matrix_equations` that lay out equations.

The dynamics these functions take is an :class:`eomgen.dynamics.Dynamics`; it is passed in,
not imported (``Dynamics`` in annotations names it): presentation reads a derivation, and a
module that formats one has no need of the machinery that makes it.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import sympy as sp

from ..symbolic.textbook import (TEXTBOOK_MAX_DOF, TEXTBOOK_MAX_OPERATIONS, TextbookDerivation,
                                 description_floats)
from .printer import DerivationLatexPrinter, display_width, latex_escape

#: Parameter names that would print like the document's own quantities (K_{1}, M_{1,2},
#: \Gamma_{1,1,2}, s_{12}, …); such parameters print as upright text instead.
_NOTATION_NAMES = re.compile(
    r"^(?:(?:K|P|g|R|pc|Jv|Ic|tau)[0-9]+|(?:M|C)[0-9]+_[0-9]+|Gamma[0-9]+_[0-9]+_[0-9]+"
    r"|[sc][0-9]+(?:_[0-9]+)*)$"
)

@dataclass(frozen=True)
class LatexConfig:
    """Options of the LaTeX backend.

    Attributes
    ----------
    template:
        The document template, below ``templates/``.
    suffix:
        Appended to the job's stem to name the file.
    float_digits:
        None (default): numbers print as the shortest decimal that reads back as the same
        double (``0.3``, ``0.3333333333333333``); an integer rounds them to that many
        significant digits for a shorter, lossy page (the generated code keeps all digits).
    line_width:
        About how many glyphs a display line holds before a sum is broken.
    block_size:
        Equations per ``align*`` environment (each may break across pages).
    textbook_max_dof, textbook_max_operations, textbook_max_size:
        The largest model given the textbook derivation: number of joints, operations of the
        straight-line program of M, C and g (checked first, it costs nothing), and operations
        of the expanded M, C and g of the textbook derivation (checked after computing it).
        The default operation bound is :data:`~eomgen.symbolic.textbook.TEXTBOOK_MAX_OPERATIONS`,
        shared by ``derive``'s default ``simplify``, the display, the notebook, the handout and
        this document.
    max_program_lines:
        At most this many named subexpressions are printed for large models.
    """

    template: str = "latex/document.tex.jinja"
    suffix: str = ".tex"
    float_digits: int | None = None
    line_width: int = 80
    block_size: int = 24
    textbook_max_dof: int = TEXTBOOK_MAX_DOF
    textbook_max_operations: int = TEXTBOOK_MAX_OPERATIONS
    textbook_max_size: int = 4000
    max_program_lines: int = 2500


@dataclass(frozen=True)
class Equation:
    """One displayed equation: ``lhs = lines[0]``, continued on ``lines[1:]``."""

    lhs: str
    lines: list[str]


@dataclass(frozen=True)
class Block:
    """Equations typeset together (one ``align*``)."""

    equations: list[Equation]


@dataclass
class Printing:
    """The printers and sizes one document uses."""

    printer: DerivationLatexPrinter
    width: int
    block_size: int

    def tex(self, expr) -> str:
        return self.printer.doprint(sp.sympify(expr))

    def equation(self, lhs: str, expr) -> Equation:
        return Equation(lhs, self.printer.print_lines(expr, self.width))

    def chunks(self, equations: list[Equation]) -> list[Block]:
        """``equations`` in blocks of at most ``block_size``."""
        size = self.block_size
        return [Block(equations[k:k + size]) for k in range(0, len(equations), size)]


def expanded_size(book: TextbookDerivation) -> int:
    """Operations (SymPy ``count_ops``) of the expanded M, C and g of ``book``."""
    return int(sum(sp.count_ops(e) for matrix in (book.M, book.C, book.g) for e in matrix))


def teaching_sized(dynamics: Dynamics, config: LatexConfig = LatexConfig()) -> bool:
    """Whether the textbook derivation of ``dynamics``' model is worth computing: few joints
    and a small program (:class:`LatexConfig`). Costs nothing next to the derivation: it
    looks at the straight-line program only. Never for coupled joints nor quaternion joints
    (the textbook form takes every joint as a coordinate)."""
    return (not dynamics.model.couplings and dynamics.model.nq == dynamics.model.dof
            and dynamics.model.dof <= config.textbook_max_dof
            and dynamics.operation_count(["M", "C", "g"]) <= config.textbook_max_operations)


def textbook_for(dynamics: Dynamics,
                 config: LatexConfig = LatexConfig()) -> TextbookDerivation | None:
    """The textbook derivation of ``dynamics``' model when it is teaching-sized (see
    :class:`LatexConfig`), else None: documents then print the straight-line program."""
    if not teaching_sized(dynamics, config):
        return None
    # computed once per Dynamics, shared with dyn.M and the display
    book = dynamics.textbook
    return book if expanded_size(book) <= config.textbook_max_size else None


#: LaTeX of entry ``k`` (1-based) of the input vectors written with a subscript of their own:
#: the Slotine–Li reference velocity and acceleration, ``\dot{q}_{r,2}`` (the handout's and
#: docs/control.md's notation; SymPy alone would print ``qd_r2`` as ``\textrm{qd\_r2}``).
VECTOR_ENTRIES = {
    "qd_r": r"\dot{{q}}_{{r,{k}}}",
    "qdd_r": r"\ddot{{q}}_{{r,{k}}}",
}


def symbol_names(dyn: Dynamics) -> dict[sp.Symbol, str]:
    """Explicit LaTeX for the joint symbols and the entries of :data:`VECTOR_ENTRIES`' input
    vectors, and for parameters whose name would print like one of the document's own
    quantities."""
    names: dict[sp.Symbol, str] = {}
    for k, (q, qd, qdd) in enumerate(zip(dyn.q, dyn.qd, dyn.qdd), start=1):
        names[q] = f"q_{{{k}}}"
        names[qd] = rf"\dot{{q}}_{{{k}}}"
        names[qdd] = rf"\ddot{{q}}_{{{k}}}"
    vectors = dyn.input_symbols
    for vector, tex in VECTOR_ENTRIES.items():
        for k, symbol in enumerate(vectors.get(vector, ()), start=1):
            names[symbol] = tex.format(k=k)
    for p in dyn.model.parameters:
        if _NOTATION_NAMES.match(p.name):
            names[p.symbol] = r"\textrm{" + latex_escape(p.name) + "}"
    return names


def printing(dynamics: Dynamics, config: LatexConfig, compact_trig: bool,
             extra_names: dict | None = None) -> Printing:
    """The printers and sizes of a derivation document of ``dynamics``; ``extra_names`` gives
    the LaTeX of further symbols (a document's own abbreviations)."""
    printer = DerivationLatexPrinter({
        "joint_positions": dynamics.q,
        "symbol_names": {**symbol_names(dynamics), **(extra_names or {})},
        "compact_trig": compact_trig,
        "float_digits": config.float_digits,
        "written_floats": description_floats(dynamics.model),
        "mat_str": "pmatrix",
        "mat_delim": "",
    })
    return Printing(printer, config.line_width, config.block_size)


# -- layout ---------------------------------------------------------------------------------

def vector(p: Printing, values) -> str:
    return r"\left(" + ", ".join(p.tex(v) for v in values) + r"\right)"


def _angle(value: float) -> sp.Expr:
    """An angle [rad] for display: a multiple of π/12 as such (``\\frac{\\pi}{2}``), else the
    number."""
    twelfths = value / math.pi * 12
    if abs(twelfths - round(twelfths)) < 1e-9:
        return sp.Rational(round(twelfths), 12) * sp.pi
    return sp.Float(value, 15)


def rpy(rotation) -> list[sp.Expr] | None:
    """URDF roll, pitch, yaw of a numeric rotation matrix, None when it is symbolic."""
    try:
        R = [[float(v) for v in row] for row in rotation]
    except TypeError:
        return None
    pitch = math.asin(max(-1.0, min(1.0, -R[2][0])))
    roll = math.atan2(R[2][1], R[2][2])
    yaw = math.atan2(R[1][0], R[0][0])
    return [_angle(a) for a in (roll, pitch, yaw)]


DH_HEADINGS = {"joint": "joint", "type": "type", "a": "$a$", "alpha": r"$\alpha$",
                "d": "$d$", "theta": r"$\theta$"}


def matrix_equations(p: Printing, lhs: str, matrix: sp.Matrix) -> list[Equation]:
    """``lhs = (matrix)`` on one line when it fits, else one line per non-zero entry."""
    entries = [p.tex(e) for e in matrix]
    widths = [max(display_width(entries[r * matrix.cols + c]) for r in range(matrix.rows))
              for c in range(matrix.cols)]
    if sum(widths) + 2 * matrix.cols <= p.width:
        rows = [" & ".join(entries[r * matrix.cols:(r + 1) * matrix.cols])
                for r in range(matrix.rows)]
        return [Equation(lhs, [r"\begin{pmatrix} " + r" \\ ".join(rows) + r" \end{pmatrix}"])]
    out = []
    for r in range(matrix.rows):
        for c in range(matrix.cols):
            if matrix[r, c] != 0:
                out.append(p.equation(rf"\bigl[{lhs}\bigr]_{{{r + 1},{c + 1}}}", matrix[r, c]))
    return out
