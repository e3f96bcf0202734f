"""Rich display in Jupyter: :meth:`RobotModel._repr_html_` and :meth:`Dynamics._repr_latex_`.

* a model shows as an HTML table of its joints (name, type, parent, child, axis), every piece of
  user text escaped with :func:`html.escape`;
* equations of motion show as LaTeX: ``M``, ``C`` and ``g`` in the notation of eomgen's
  derivation documents (``s_{1}``, ``c_{12}``, ``\\dot{q}_{1}``) for models of at most
  :data:`DISPLAY_MAX_DOF` joints; larger models show a short summary (joints, operation counts)
  instead of pages of algebra.

The printing is :mod:`eomgen.present`'s, shared with the LaTeX document, the handout and the
notebook. The model and dynamics shown (``RobotModel``, ``Dynamics`` in annotations) are passed
in, not imported: the data classes find these renderers through :mod:`eomgen.common.reprs`.
"""

from __future__ import annotations

import html

from ..common import reprs

#: Models with more joints display a summary instead of M, C and g.
DISPLAY_MAX_DOF = 3


def _number(value) -> str:
    """A number as the shortest decimal that reads back as the same double (``0.3``, ``1``),
    scientific as ``1.5e-05``; a symbolic parameter by its name."""
    try:
        value = float(value)
    except TypeError:  # a symbolic parameter
        return str(value)
    return str(int(value)) if value.is_integer() and abs(value) < 2 ** 53 else repr(value)


def model_html(model: RobotModel) -> str:
    """An HTML table of ``model``'s joints, every name escaped.

    >>> import eomgen
    >>> print(model_html(eomgen.load(eomgen.example_path("planar_2link"))).splitlines()[0])
    <div class="eomgen-model"><p><b>planar_2link</b>: 2 movable joints (joint1, joint2)</p>
    """
    e = html.escape
    movable = model.dof
    rows = []
    for joint in model.joints:
        axis = ", ".join(_number(x) for x in joint.axis) if joint.type.is_movable else ""
        rows.append("<tr>" + "".join(f"<td>{e(str(x))}</td>" for x in (
            joint.name, joint.type.name.lower(), joint.parent, joint.child,
            f"({axis})" if axis else "")) + "</tr>")
    header = "".join(f"<th>{h}</th>" for h in ("joint", "type", "parent", "child", "axis"))
    names = ", ".join(e(n) for n in model.joint_names)
    return (f'<div class="eomgen-model"><p><b>{e(model.name)}</b>: {movable} movable joint'
            f'{"" if movable == 1 else "s"} ({names})</p>\n'
            f"<table>\n<thead><tr>{header}</tr></thead>\n<tbody>\n" + "\n".join(rows)
            + "\n</tbody>\n</table></div>")


def _printer(dynamics: Dynamics, names: dict | None = None):
    from .notation import LatexConfig, printing  # start-up time (SymPy)

    return printing(dynamics, LatexConfig(), compact_trig=True, extra_names=names).printer


def _text(value: str) -> str:
    from .printer import latex_escape  # start-up time (SymPy)

    return r"\text{" + latex_escape(value) + "}"


def readable_matrices(dynamics: Dynamics) -> dict | None:
    """M, C and g of ``dynamics`` as the LaTeX document and the handout print them (the
    textbook derivation, entries of M grouped by body mass, those of g by trigonometric
    factor), or None when the model is not teaching-sized (the bounds of
    :func:`eomgen.present.notation.textbook_for`, checked on the program's size before anything
    is expanded) and ``derive(..., simplify=True)`` did not force it."""
    from .notation import textbook_for  # start-up time (SymPy)

    if dynamics.simplified:  # derive(..., simplify=True) asked for it whatever the size
        book = dynamics.textbook
    else:
        book = textbook_for(dynamics)
        if book is None:
            return None
    return grouped_matrices(book)


def grouped_matrices(book) -> dict:
    """M, C and g of a :class:`~eomgen.symbolic.textbook.TextbookDerivation` as every document
    prints them: entries of M grouped by body mass, those of g by trigonometric factor (sums
    built unevaluated, so their order is kept; print them with :func:`expression_latex`). Kept
    here for notebooks; the grouping is :func:`eomgen.present.grouping.grouped_matrices`."""
    from . import grouping  # start-up time (SymPy)

    return grouping.grouped_matrices(book)


def dynamics_latex(dynamics: Dynamics, max_dof: int = DISPLAY_MAX_DOF) -> str:
    """LaTeX (one ``$$…$$`` display) of ``dynamics``: M, C, g for small models, else a summary.

    Small models (at most ``max_dof`` joints and within the size bounds of
    :func:`readable_matrices`) show M, C and g in the reduced forms of the LaTeX document and
    the handout; others show the operation counts of the straight-line program, which cost
    nothing to compute.

    >>> import eomgen
    >>> tex = dynamics_latex(eomgen.derive(eomgen.load(eomgen.example_path("planar_2link"))))
    >>> "c_{2}" in tex and tex.startswith("$$")
    True
    """
    model = dynamics.model
    title = _text(f"{model.name}: {model.dof} joints ({', '.join(model.joint_names)})")
    matrices = readable_matrices(dynamics) if model.dof <= max_dof else None
    if matrices is None:
        counts = ",\\ ".join(
            _text(f"{name}: {dynamics.operation_count([name])} operations")
            for name in dynamics.outputs)
        if model.dof > max_dof:
            why = f"models of at most {max_dof} joints"
        else:
            why = ("teaching-sized models; derive(model, simplify=True) forces the expanded "
                   "textbook form, which takes long for this one")
        return ("$$\\begin{array}{l}" + title + r"\\ " + counts + r"\\ "
                + _text(f"(M, C, g are shown for {why}; numbers: dynamics.lambdify())")
                + r"\end{array}$$")
    printer = _printer(dynamics)
    lines = [title]
    for name in ("M", "C", "g"):
        if name in dynamics.outputs:
            lines.append(f"{name} = {_matrix_latex(printer, matrices[name])}")
    return "$$\\begin{array}{l}" + r"\\[1ex] ".join(lines) + r"\end{array}$$"


def _matrix_latex(printer, matrix) -> str:
    """A ``pmatrix``; the grouped sums of :func:`readable_matrices` keep their order (masses
    first, as the LaTeX document and the handout print them)."""
    def entry(e):
        if e.is_Add and _unevaluated(e):
            return printer.print_sum_lines(list(e.args), 10 ** 9)[0]
        return printer.doprint(e)

    rows = [" & ".join(entry(matrix[r, c]) for c in range(matrix.cols))
            for r in range(matrix.rows)]
    return r"\begin{pmatrix}" + r"\\".join(rows) + r"\end{pmatrix}"


def _unevaluated(e) -> bool:
    """Whether the sum ``e`` was built with ``evaluate=False`` (a grouped sum)."""
    import sympy as sp  # start-up time: `import eomgen` imports this module

    return e.args != sp.Add(*e.args).args


def expression_latex(dynamics: Dynamics, expr, names: dict | None = None) -> str:
    """LaTeX of one expression or matrix in the notation of :func:`dynamics_latex`; grouped
    sums (:func:`grouped_matrices`) keep their order, as in :func:`dynamics_latex`. ``names``
    gives the LaTeX of further symbols (e.g. :attr:`eomgen.regressor.RegressorForm.
    latex_names` for the inertial parameters).

    >>> import eomgen
    >>> dyn = eomgen.derive(eomgen.load(eomgen.example_path("planar_2link")))
    >>> expression_latex(dyn, dyn.g[1])
    'g l_{c2} m_{2} c_{12}'
    """
    import sympy as sp  # start-up time: `import eomgen` imports this module

    printer = _printer(dynamics, names)
    if isinstance(expr, sp.MatrixBase):
        return _matrix_latex(printer, expr)
    if isinstance(expr, sp.Add) and _unevaluated(expr):
        return printer.print_sum_lines(list(expr.args), 10 ** 9)[0]
    return printer.doprint(expr)


# What RobotModel._repr_html_ and Dynamics._repr_latex_ show (eomgen.common.reprs).
reprs.register("model", "text/html", model_html)
reprs.register("dynamics", "text/latex", dynamics_latex)
