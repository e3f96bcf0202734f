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

This module only registers the backend and renders the document: its content and notation are
presentation, in :mod:`eomgen.present` (:mod:`~eomgen.present.sections` builds the sections,
:mod:`~eomgen.present.notation` holds :class:`LatexConfig`, :func:`printing` and
:func:`textbook_for`), shared with the handout, the notebook and the Jupyter display; the names
once defined here are re-exported from there. Printer:
:class:`~eomgen.present.printer.DerivationLatexPrinter`. Template:
``templates/latex/document.tex.jinja``. Every string that comes from the description (robot,
link, joint and file names, descriptions) is escaped with
:func:`~eomgen.present.printer.latex_escape`.
"""

from __future__ import annotations

from ...present.notation import (  # noqa: F401  (re-exported: once defined here)
    DH_HEADINGS, Block, Equation, LatexConfig, Printing, expanded_size, matrix_equations,
    printing, rpy, symbol_names, teaching_sized, textbook_for, vector,
)
from ...present.sections import (  # noqa: F401  (re-exported: once defined here)
    PROGRAM_NAMES, document_context, program_sections,
)
from ...common.output import GeneratedFile
from ..job import Job
from ..registry import register
from ...common.templating import render


def render_document(job: Job, config: LatexConfig = LatexConfig()) -> str:
    """The text of the ``.tex`` document for ``job`` (see the module docstring)."""
    context = document_context(job.dynamics, config, job.header_lines(config.template),
                               job.source_name)
    return render(config.template, **context)


@register("latex", "LaTeX document of the derivation: textbook steps for small models, the "
                   "program of named subexpressions for large ones (pdflatex)",
          needs=("M", "C", "g"), config=LatexConfig, order=50)
def generate_latex(job: Job, config: LatexConfig = LatexConfig()) -> list[GeneratedFile]:
    return [GeneratedFile(job.stem + config.suffix, render_document(job, config))]
