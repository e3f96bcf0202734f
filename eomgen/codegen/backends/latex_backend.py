"""LaTeX backend: ``<robot>.tex``, a standalone document of the derivation (plain pdflatex with
amsmath, geometry and longtable; all three are in TeX Live's ``latex-base``).

Two kinds of document, chosen by :func:`textbook_for`:

* **teaching-sized** models (at most :data:`~eomgen.symbolic.textbook.TEXTBOOK_MAX_DOF` joints
  and expressions of moderate size): the textbook derivation of :mod:`eomgen.symbolic.textbook`,
  body by body: centre-of-mass positions, Jacobians, K_i and P_i, then M, the Christoffel
  symbols, C, g and the equations of motion written out, in compact trigonometric notation
  (s_1, c_12); then the linear parameterization τ = Y π with its columns named and the base
  parameters β as expressions of π (:attr:`eomgen.dynamics.Dynamics.regressor_form`);
* **large** models: the description, then the straight-line program of named subexpressions
  that computes M, g and C (grouped by the output that first needs them), the entries of M, C,
  g in terms of those names and the equations of motion per joint. At most
  :attr:`LatexConfig.max_program_lines` subexpressions are printed, so that pdflatex stays fast.
  The regressor is not written out (a sentence says where to find it).

Printer: :class:`~eomgen.codegen.backends.latex_printer.DerivationLatexPrinter`. Template:
``templates/latex/document.tex.jinja``. Every string that comes from the description (robot,
link, joint and file names, descriptions) is escaped with
:func:`~eomgen.codegen.backends.latex_printer.latex_escape`.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import sympy as sp

from ... import __version__
from ...dynamics import Dynamics
from ...model import IDENTITY3, RobotModel
from ...symbolic.textbook import (TEXTBOOK_MAX_DOF, TEXTBOOK_MAX_OPERATIONS, TextbookDerivation,
                                   description_floats)
from .. import GeneratedFile, Job, register
from ..render import render
from .latex_printer import (DerivationLatexPrinter, display_width, latex_comment, latex_escape,
                            written_number)

#: Parameter names that would print like the document's own quantities (K_{1}, M_{1,2},
#: \Gamma_{1,1,2}, s_{12}, …); such parameters print as upright text instead.
_NOTATION_NAMES = re.compile(
    r"^(?:(?:K|P|g|R|pc|Jv|Ic|tau)[0-9]+|(?:M|C)[0-9]+_[0-9]+|Gamma[0-9]+_[0-9]+_[0-9]+"
    r"|[sc][0-9]+(?:_[0-9]+)*)$"
)

#: The families of named subexpressions of eomgen's straight-line program (the
#: :class:`~eomgen.symbolic.program.Tag` families :mod:`eomgen.symbolic.composite` sets) and what
#: they are, in LaTeX, for the legend of large
#: documents. Vectors and matrices are in world coordinates; spatial 6-vectors are
#: [angular; linear] about the reference point o, the first moving joint's origin.
PROGRAM_NAMES = {
    "s": r"$\sin q_{i}$",
    "c": r"$\cos q_{i}$",
    "A": r"rotation of joint frame $i$ before the joint moves, entry $(r, c)$",
    "R": r"rotation of body $i$, entry $(r, c)$",
    "o": r"origin of joint frame $i$, from the first joint's origin $o$",
    "p": r"origin of body $i$ (moved by its prismatic joint)",
    "z": r"axis of joint $i$",
    "v": r"linear part $o_{i} \times z_{i}$ of the motion axis $S_{i}$ of joint $i$",
    "Rh": r"first moment of body $i$ in world axes",
    "Iw": r"rotational inertia of body $i$ about the first joint's origin $o$, entry $(r, c)$",
    "hw": r"first moment of body $i$ about the first joint's origin $o$",
    "mc": r"mass of the subtree of body $i$ (composite body)",
    "hc": r"first moment of composite body $i$",
    "Ic": r"rotational inertia $I^{c}_{i}$ of composite body $i$ about the first joint's "
          r"origin $o$, entry $(r, c)$",
    "F": r"momentum $F_{i} = I^{c}_{i} S_{i}$ of composite body $i$ for a unit rate of joint $i$",
    "M": r"entry $(i, j)$ of the mass matrix, $S_{i}^{T} F_{j}$",
    "g": r"entry $i$ of the gravity vector",
    "X": r"motion cross product $S_{k} \times S_{j}$",
    "G": r"momentum $I^{c}_{k} S_{j}$ of composite body $k$ for a unit rate of joint $j$",
    "Y": r"force cross product $S_{k} \times^{*} F_{j}$",
    "dM": r"$\partial M_{i,j} / \partial q_{k}$",
    "Gamma": r"Christoffel symbol of the first kind $\Gamma_{i,j,k}$",
    "C": r"entry $(i, j)$ of the Coriolis matrix",
    # body-frame recursions (Newton-Euler, CRBA, Echeandia-Wensing, ABA): every vector in the
    # axes of body i (its joint frame after the joint moved), about its origin
    "wp": r"angular velocity of the parent of body $i$, in body $i$ axes",
    "w": r"angular velocity $\omega_{i}$ of body $i$",
    "dw": r"angular acceleration $\dot\omega_{i}$ of body $i$",
    "ap": r"acceleration of the origin of body $i$ (gravity as a base acceleration; over a "
          r"length $L$ when all numbers are known), parent axes",
    "a": r"acceleration of the origin of body $i$ (gravity as a base acceleration; over a "
         r"length $L$ when all numbers are known)",
    "ww": r"product $\omega_{r} \omega_{c}$ of the angular velocity of body $i$",
    "U": r"entry $(r, c)$ of $U_{i} = [\dot\omega_{i}]_\times + [\omega_{i}]_\times^{2}$",
    "wd": r"difference of squares $\omega_{j}^{2} - \omega_{k}^{2}$ of the angular velocity of "
          r"body $i$ ($(i, j, k)$ cyclic), for $I \dot\omega + \omega \times I \omega$",
    "qp": r"angle $q_{i} + \varphi_{i}$ of a last body described in axes turned by $\varphi_{i}$ "
          r"about its joint axis",
    "f": r"force on body $i$ from its parent, body $i$ axes",
    "n": r"moment on body $i$ from its parent, about its origin",
    "fp": r"force of body $i$ on its parent, parent axes",
    "effort": r"effort of joint $i$ from the Newton--Euler recursion",
    "Icb": r"composite spatial inertia of body $i$ in its axes, block $(r, c)$ of $I$, $[h]_\times$ "
           r"or $m 1$",
    "RX": r"a composite inertia block of body $i$ rotated into its parent's axes (first half)",
    "XIX": r"a composite inertia block of body $i$ in its parent's axes",
    "shift": r"a composite inertia block of body $i$ moved to its parent's origin",
    "Fbody": r"$I^{c}_{j} S_{j}$ of composite body $j$, in the axes of its ancestor $i$",
    "Sd": r"rate $\dot S_{i} = V_{\lambda(i)} \times S_{i}$ of the motion axis of joint $i$",
    "V": r"spatial velocity $V_{i}$ of body $i$",
    "hV": r"momentum $I_{i} V_{i}$ of body $i$, summed over its subtree",
    "hd": r"rate of the first moment of body $i$, summed over its subtree",
    "Id": r"rate of the rotational inertia of body $i$, summed over its subtree, entry $(r, c)$",
    "Fa": r"$I^{c}_{j} \dot S_{j} + \tfrac12 (\dot I^{c}_{j} S_{j} + S_{j} \times^{*} h^{c}_{j})$ "
          r"(Echeandia and Wensing)",
    "Fb": r"$\tfrac12 (\dot I^{c}_{j} S_{j} - S_{j} \times^{*} h^{c}_{j})$ (Echeandia and "
          r"Wensing)",
    "Cqd": r"entry $i$ of $C \dot q = h - g$",
    "Vb": r"spatial velocity of body $i$ in its axes",
    "cb": r"velocity-product acceleration of body $i$",
    "hb": r"spatial momentum of body $i$",
    "pA": r"bias force of articulated body $i$",
    "UA": r"$U_{i} = I^{A}_{i} S_{i}$ of articulated body $i$",
    "D": r"$D_{i} = S_{i}^{T} U_{i}$",
    "Dinv": r"$1 / D_{i}$",
    "u": r"$u_{i} = \tau_{i} - S_{i}^{T} p^{A}_{i}$",
    "Ud": r"$U_{i} / D_{i}$",
    "Ia": r"articulated inertia handed to the parent of body $i$, entry $(r, c)$",
    "IAb": r"articulated spatial inertia of body $i$, block $(r, c)$",
    "pa": r"bias force handed to the parent of body $i$",
    "aprime": r"acceleration of body $i$ before its own joint's",
    "qdd": r"joint acceleration $\ddot q_{i}$",
    "ab": r"spatial acceleration of body $i$",
    "L": r"entry $(i, j)$ of the Cholesky factor $L$ of $M$",
    "Linv": r"$1 / L_{i,i}$",
    "ychol": r"entry $i$ of $L^{-1} (\tau - h)$",
}

_PROGRAM_GROUPS = (
    ("M", "Subexpressions of the mass matrix"),
    ("g", "Further subexpressions of the gravity vector"),
    ("C", "Further subexpressions of the Coriolis matrix"),
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
    looks at the straight-line program only."""
    return (dynamics.model.dof <= config.textbook_max_dof
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


def symbol_names(dyn: Dynamics) -> dict[sp.Symbol, str]:
    """Explicit LaTeX for the joint symbols, and for parameters whose name would print like one
    of the document's own quantities."""
    names: dict[sp.Symbol, str] = {}
    for k, (q, qd, qdd) in enumerate(zip(dyn.q, dyn.qd, dyn.qdd), start=1):
        names[q] = f"q_{{{k}}}"
        names[qd] = rf"\dot{{q}}_{{{k}}}"
        names[qdd] = rf"\ddot{{q}}_{{{k}}}"
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


def vector(p: Printing, values) -> str:
    return r"\left(" + ", ".join(p.tex(v) for v in values) + r"\right)"


# -- the description ------------------------------------------------------------------------

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


def _joint_rows(model: RobotModel, p: Printing) -> list[list[str]]:
    rows = []
    index = {j.name: k for k, j in enumerate(model.movable_joints, start=1)}
    for joint in model.joints:
        rotation = joint.origin.rotation
        if rotation == IDENTITY3:
            angles_tex = "0"
        else:
            angles = rpy(rotation)
            angles_tex = "$" + vector(p, angles) + "$" if angles is not None else "symbolic"
        rows.append([
            f"$q_{{{index[joint.name]}}}$" if joint.name in index else "",
            latex_escape(joint.name),
            joint.type.value,
            latex_escape(joint.parent),
            latex_escape(joint.child),
            "$" + vector(p, joint.axis) + "$" if joint.type.is_movable else "",
            "$" + vector(p, joint.origin.translation) + "$",
            angles_tex,
        ])
    return rows


DH_HEADINGS = {"joint": "joint", "type": "type", "a": "$a$", "alpha": r"$\alpha$",
                "d": "$d$", "theta": r"$\theta$"}


def _dh_table(model: RobotModel, p: Printing) -> dict | None:
    info = dict(model.info)
    if "dh" not in info:
        return None
    columns = list(info.get("dh_columns", ("joint", "type", "a", "alpha", "d", "theta")))
    rows = []
    for row in info["dh"]:
        cells = []
        for value in row:
            if isinstance(value, sp.Basic):
                cells.append("$" + p.tex(value) + "$")
            else:
                cells.append(latex_escape(str(value)))
        rows.append(cells)
    return {
        "convention": latex_escape(str(info.get("convention", ""))),
        "headings": [DH_HEADINGS.get(c, latex_escape(c)) for c in columns],
        "rows": rows,
    }


def _link_rows(model: RobotModel, p: Printing) -> list[list[str]]:
    rows = []
    for link in model.links:
        if link.inertial is None:
            rows.append([latex_escape(link.name), "--", "", ""])
            continue
        inertia = link.inertial.inertia
        rows.append([
            latex_escape(link.name),
            "$" + p.tex(link.inertial.mass) + "$",
            "$" + vector(p, link.inertial.com) + "$",
            "$" + vector(p, [inertia[0][0], inertia[1][1], inertia[2][2],
                              inertia[0][1], inertia[0][2], inertia[1][2]]) + "$",
        ])
    return rows


def _parameter_rows(model: RobotModel, p: Printing) -> list[list[str]]:
    return [["$" + p.tex(par.symbol) + "$",
             "$" + p.tex(written_number(par.value)) + "$" if par.value is not None else "--",
             latex_escape(par.description)]
            for par in sorted(model.parameters, key=lambda par: par.name)]


# -- the textbook derivation ----------------------------------------------------------------

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


def _textbook_sections(job: Job, book: TextbookDerivation, p: Printing) -> dict:
    n = job.model.dof
    bodies = []
    for body in book.bodies:
        k = job.model.joint_names.index(body.joint) + 1
        kinematics = matrix_equations(p, f"I_{{c{k}}}", body.inertia)
        kinematics += matrix_equations(p, f"R_{{{k}}}", body.rotation)
        kinematics += matrix_equations(p, f"p_{{c{k}}}", body.com)
        kinematics += matrix_equations(p, f"J_{{v{k}}}", body.J_v)
        kinematics += matrix_equations(p, rf"J_{{\omega {k}}}", body.J_w)
        energies = [p.equation(f"K_{{{k}}}", body.K), p.equation(f"P_{{{k}}}", body.P)]
        bodies.append({
            "index": k,
            "joint": latex_escape(body.joint),
            "links": ", ".join(latex_escape(name) for name in body.links),
            "mass": p.tex(body.mass),
            "kinematics": p.chunks(kinematics),
            "energies": p.chunks(energies),
        })
    from ...teach import readability as rd  # the handout's and the display's grouping

    def grouped(lhs, terms):
        return Equation(lhs, p.printer.print_sum_lines(terms or [sp.Integer(0)], p.width))

    masses = [b.mass for b in book.bodies if isinstance(b.mass, sp.Symbol)]
    M = [grouped(f"M_{{{i + 1},{j + 1}}}", rd.by_mass(book.M[i, j], masses))
         for i in range(n) for j in range(i, n)]
    christoffel = []
    for (i, j, k), value in book.christoffel:
        lhs = rf"\Gamma_{{{i + 1},{j + 1},{k + 1}}}"
        if j != k:
            lhs += rf" = \Gamma_{{{i + 1},{k + 1},{j + 1}}}"
        christoffel.append(p.equation(lhs, value))
    C = [p.equation(f"C_{{{i + 1},{j + 1}}}", book.C[i, j]) for i in range(n) for j in range(n)]
    dyn = job.dynamics
    g = [grouped(f"g_{{{i + 1}}}", rd.by_trig(book.g[i], list(dyn.q))) for i in range(n)]
    equations = []
    for i in range(n):
        terms = [book.M[i, j] * dyn.qdd[j] for j in range(n) if book.M[i, j] != 0]
        terms += [book.C[i, j] * dyn.qd[j] for j in range(n) if book.C[i, j] != 0]
        terms += [book.g[i]] if book.g[i] != 0 else []
        lines = p.printer.print_sum_lines(terms or [sp.Integer(0)], p.width)
        equations.append(Equation(rf"\tau_{{{i + 1}}}", lines))
    return {
        "bodies": bodies,
        "energies": p.chunks([p.equation("K", book.K), p.equation("P", book.P)]),
        "M_blocks": p.chunks(M),
        "christoffel": p.chunks(christoffel),
        "coriolis": p.chunks(C),
        "g_blocks": p.chunks(g),
        "equations": p.chunks(equations),
    }


# -- the straight-line program --------------------------------------------------------------

def _entry_symbol(name: str, *indices: int) -> sp.Symbol:
    """The symbol printing as an entry of M, C or g: ``M1_2`` → ``M_{1,2}`` (0-based indices)."""
    return sp.Symbol(name + "_".join(str(i + 1) for i in indices), real=True)


def _entries(p: Printing, name: str, matrix: sp.Matrix, upper: bool = False) -> list[Equation]:
    """``name_{i,j} = value`` for the non-zero entries, except those already named so."""
    out = []
    for i in range(matrix.rows):
        for j in range(i if upper else 0, matrix.cols):
            value = matrix[i, j]
            entry = _entry_symbol(name, i, j) if matrix.cols > 1 else _entry_symbol(name, i)
            if value != 0 and value != entry:
                out.append(p.equation(p.tex(entry), value))
    return out


def program_sections(dyn: Dynamics, config: LatexConfig, p: Printing) -> dict:
    """The named subexpressions of ``dyn``'s program, grouped by the output that first needs
    them (at most ``config.max_program_lines``), the entries of M, g, C and the equations of
    motion in terms of them."""
    program = dyn.program
    n = dyn.model.dof
    shown: set[sp.Symbol] = set()
    groups, omitted = [], []
    legend: dict[str, str] = {}
    budget = config.max_program_lines
    tags = program.tags()  # what each intermediate is, set where it was defined
    for output, title in _PROGRAM_GROUPS:
        assignments = [(s, e) for s, e in program.pruned([output]).assignments if s not in shown]
        if len(assignments) > budget:
            omitted.append(output)
            continue
        budget -= len(assignments)
        shown |= {s for s, _ in assignments}
        for symbol, _ in assignments:
            family = tags[symbol].family if symbol in tags else None
            if family in PROGRAM_NAMES and family not in legend:
                legend[family] = p.tex(symbol)
        equations = [p.equation(p.tex(symbol), expr) for symbol, expr in assignments]
        groups.append({"title": title, "count": len(assignments), "blocks": p.chunks(equations)})

    M, C, g = (program.output(name) for name in ("M", "C", "g"))
    outputs = {
        "M": [] if "M" in omitted else p.chunks(_entries(p, "M", M, upper=True)),
        "g": [] if "g" in omitted else p.chunks(_entries(p, "g", g)),
        "C": [] if "C" in omitted else p.chunks(_entries(p, "C", C)),
    }
    equations = []
    for i in range(n):
        terms = [_entry_symbol("M", min(i, j), max(i, j)) * dyn.qdd[j] for j in range(n)
                 if M[i, j] != 0]
        terms += [_entry_symbol("C", i, j) * dyn.qd[j] for j in range(n) if C[i, j] != 0]
        terms += [_entry_symbol("g", i)] if g[i] != 0 else []
        equations.append(Equation(rf"\tau_{{{i + 1}}}",
                                  p.printer.print_sum_lines(terms or [sp.Integer(0)], p.width)))
    return {
        "legend": [(tex, PROGRAM_NAMES[family]) for family, tex in legend.items()],
        "groups": groups,
        "omitted": [{"M": "mass matrix", "g": "gravity vector", "C": "Coriolis matrix"}[o]
                    for o in omitted],
        "total": len(program.pruned(["M", "C", "g"]).assignments),
        "outputs": outputs,
        "equations": p.chunks(equations),
    }


# -- the regressor (teaching-sized models) --------------------------------------------------

def _regressor_sections(form, p: Printing) -> dict:
    """τ = Y π with the non-zero columns named, entry by entry, and β(π)."""
    from ...regressor import parameter_latex

    reg = form.regressor
    entries = []
    for c, k in enumerate(form.columns):
        column = parameter_latex(reg.PARAMETER_NAMES[k])
        for i in range(reg.n):
            if form.Y[i, c] != 0:
                entries.append(p.equation(rf"\bigl[Y\bigr]_{{{i + 1},\,{column}}}", form.Y[i, c]))
    beta = []
    for k, name, expr in zip(form.base, form.base_names, form.beta):
        own = reg.parameter_symbols[k]
        if expr != own:  # the column's own parameter first, then what is grouped into it
            terms = ([own] + list(sp.Add.make_args(expr - own))
                     if own in sp.Add.make_args(expr) else [expr])
            beta.append(Equation(parameter_latex(name),
                                 p.printer.print_sum_lines(terms, p.width)))

    def names(indices):
        return [parameter_latex(reg.PARAMETER_NAMES[k]) for k in indices]

    return {
        "pi": names(form.columns),
        "zero": names(form.zero),
        "Y_blocks": p.chunks(entries),
        "base": names(form.base),
        "beta": [parameter_latex(name) for name in form.base_names],
        "beta_blocks": p.chunks(beta),
        "exact": form.exact,
        "p": reg.p,
    }


def render_document(job: Job, config: LatexConfig = LatexConfig()) -> str:
    """The text of the ``.tex`` document for ``job`` (see the module docstring)."""
    model = job.model
    book = textbook_for(job.dynamics, config)
    form = None
    extra_names = {}
    if book is not None:  # same bound: the expanded Y of a model that small stays small
        form = job.dynamics.regressor_form
        extra_names = form.latex_names
    p = printing(job.dynamics, config, compact_trig=book is not None, extra_names=extra_names)
    context = {
        "header": [latex_comment(line) for line in job.header_lines(config.template)],
        "robot": latex_escape(model.name),
        "source": latex_escape(job.source_name),
        "version": latex_escape(__version__),
        "description": latex_escape(str(dict(model.info).get("description", ""))),
        "dof": model.dof,
        "joint_vector": {0: "()", 1: "q_{1}"}.get(model.dof,
                                                  rf"(q_{{1}}, \dots, q_{{{model.dof}}})"),
        "gravity": vector(p, model.gravity),
        "joints": _joint_rows(model, p),
        "dh": _dh_table(model, p),
        "links": _link_rows(model, p),
        "parameters": _parameter_rows(model, p),
        "float_digits": config.float_digits,
        "teaching": book is not None,
        "max_dof": config.textbook_max_dof,
        "max_operations": config.textbook_max_operations,
        "max_size": config.textbook_max_size,
        "operations": job.dynamics.operation_count(["M", "C", "g"]),
    }
    if book is not None:
        context.update(_textbook_sections(job, book, p))
        context["linear"] = _regressor_sections(form, p)
    else:
        context.update(program_sections(job.dynamics, config, p))
    return render(config.template, **context)


@register("latex", "LaTeX document of the derivation: textbook steps for small models, the "
                   "program of named subexpressions for large ones (pdflatex)",
          needs=("M", "C", "g"), config=LatexConfig, order=50)
def generate_latex(job: Job, config: LatexConfig = LatexConfig()) -> list[GeneratedFile]:
    return [GeneratedFile(job.stem + config.suffix, render_document(job, config))]
