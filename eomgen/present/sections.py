"""The derivation document's content: every section of the LaTeX document of a derivation (and,
through :func:`program_sections`, the handout's program section) as printed LaTeX strings, ready
for a template that only loops over them.

* the description: joint, DH, link and parameter tables;
* teaching-sized models (:func:`~eomgen.present.notation.textbook_for`): the textbook derivation
  body by body, M, the Christoffel symbols, C, g, the equations of motion
  (:func:`textbook_sections`) and the linear parameterization τ = Y π (:func:`regressor_sections`);
* large models: the straight-line program of named subexpressions grouped by the output that
  first needs them, with a legend read from the intermediates' tags (:data:`PROGRAM_NAMES`), and
  the entries of M, C, g in terms of those names (:func:`program_sections`).

:func:`document_context` assembles them for ``templates/latex/document.tex.jinja``; the LaTeX
backend (:mod:`eomgen.codegen.backends.latex_backend`) renders it. As in
:mod:`eomgen.present.notation`, the dynamics is passed in, not imported.
"""

from __future__ import annotations

import sympy as sp

from ..common.version import __version__
from ..model import IDENTITY3, RobotModel
from ..regressor import parameter_latex
from ..symbolic.textbook import TextbookDerivation
from . import readability as rd
from .grouping import body_masses
from .notation import (DH_HEADINGS, Equation, LatexConfig, Printing, printing, rpy,
                       matrix_equations, textbook_for, vector)
from .printer import latex_comment, latex_escape, written_number

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


# -- the description ------------------------------------------------------------------------

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

def textbook_sections(dyn: Dynamics, book: TextbookDerivation, p: Printing) -> dict:
    """The textbook derivation ``book`` of ``dyn``'s model, body by body, then M (grouped by
    body mass), the Christoffel symbols, C, g (grouped by trigonometric factor) and the
    equations of motion."""
    n = dyn.model.dof
    bodies = []
    for body in book.bodies:
        k = dyn.model.joint_names.index(body.joint) + 1
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
    def grouped(lhs, terms):
        return Equation(lhs, p.printer.print_sum_lines(terms or [sp.Integer(0)], p.width))

    masses = body_masses(book)
    M = [grouped(f"M_{{{i + 1},{j + 1}}}", rd.by_mass(book.M[i, j], masses))
         for i in range(n) for j in range(i, n)]
    christoffel = []
    for (i, j, k), value in book.christoffel:
        lhs = rf"\Gamma_{{{i + 1},{j + 1},{k + 1}}}"
        if j != k:
            lhs += rf" = \Gamma_{{{i + 1},{k + 1},{j + 1}}}"
        christoffel.append(p.equation(lhs, value))
    C = [p.equation(f"C_{{{i + 1},{j + 1}}}", book.C[i, j]) for i in range(n) for j in range(n)]
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

def regressor_sections(form, p: Printing) -> dict:
    """τ = Y π with the non-zero columns named, entry by entry, and β(π), of a
    :class:`~eomgen.regressor.RegressorForm`."""
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


# -- the document ---------------------------------------------------------------------------

def document_context(dyn: Dynamics, config: LatexConfig, header: list[str],
                     source_name: str) -> dict:
    """What ``config.template`` prints for ``dyn``: the description, then the textbook
    derivation and the regressor of a teaching-sized model or the program of a large one.
    ``header`` holds the lines the file opens with (commented here), ``source_name`` the
    description file's name."""
    model = dyn.model
    book = textbook_for(dyn, config)
    form = None
    extra_names = {}
    if book is not None:  # same bound: the expanded Y of a model that small stays small
        form = dyn.regressor_form
        extra_names = form.latex_names
    p = printing(dyn, config, compact_trig=book is not None, extra_names=extra_names)
    context = {
        "header": [latex_comment(line) for line in header],
        "robot": latex_escape(model.name),
        "source": latex_escape(source_name),
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
        "operations": dyn.operation_count(["M", "C", "g"]),
    }
    if book is not None:
        context.update(textbook_sections(dyn, book, p))
        context["linear"] = regressor_sections(form, p)
    else:
        context.update(program_sections(dyn, config, p))
    return context
