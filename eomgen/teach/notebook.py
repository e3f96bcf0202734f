"""A Jupyter notebook walking through the derivation of one robot's equations of motion
(``eomgen notebook``).

Sections, each a short explanation followed by a code cell using eomgen's API: loading the
robot; for teaching-sized models (at most :data:`~eomgen.symbolic.textbook.TEXTBOOK_MAX_DOF`
joints and :data:`~eomgen.symbolic.textbook.TEXTBOOK_MAX_OPERATIONS` program operations) the
textbook derivation (centre-of-mass positions, Jacobians, kinetic and potential energy per link,
M, Christoffel symbols, C, g); the equations of motion; for the same models the regressor
Y (τ = Y π, columns named) and the base parameters as expressions of the standard ones
(:func:`eomgen.regressor.regressor_form`); the property checks of
:func:`eomgen.verify`; a comparison with the numeric Newton–Euler algorithm at a sample state;
and a short simulation (SciPy's ``solve_ivp``) with a plot.

The cells' texts are the blocks of ``templates/notebook/cells.jinja`` (:data:`CELLS_TEMPLATE`),
one per cell; this module chooses which cells a model's notebook holds and fills in its names
and numbers. The notebook is saved without outputs and holds no timestamp: the same description
gives the same file, byte for byte.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

import nbformat
from nbformat import v4

from ..dynamics import derive
from ..errors import ParameterError
from ..model import RobotModel
from ..present.notation import teaching_sized
from ..symbolic.textbook import TEXTBOOK_MAX_DOF, TEXTBOOK_MAX_OPERATIONS
from .embedded import EmbeddedSource, embedded_source, text_literal
from .quaternion import chart_joint_names
from ..common.templating import render_block


def _teaching_sized(model: RobotModel) -> bool:
    """Whether the notebook shows the textbook derivation: the bound of the LaTeX document and
    the display, checked on the straight-line program before anything is expanded."""
    return teaching_sized(derive(model, simplify=False))


def build_notebook(model: RobotModel, description: Path | None = None,
                   scene: Path | None = None, check: bool = True,
                   at: Path | None = None) -> nbformat.NotebookNode:
    """The derivation notebook of ``model``, loaded from ``description`` (None: the bundled
    planar 2-link arm) and reduced by the scene file ``scene`` when given (``model`` is then the
    reduced model, see :func:`eomgen.reduction.apply_scene`). ``check=False`` (``--no-check``)
    leaves out the checks (:func:`eomgen.verify`, Ṁ − 2C skew-symmetric, the asserted
    comparisons): the notebook says so and only prints the numbers.

    The symbolic check of Ṁ − 2C is exact for a model with exact numbers and holds to
    :data:`~eomgen.symbolic.identities.FLOAT_TOLERANCE` when the model has floating-point
    numbers (:func:`~eomgen.symbolic.identities.check_zero`); the cell prints which.

    The description's text (and the scene's) is written into the notebook, which therefore
    runs wherever it is copied; a description naming files of its own (an MJCF's meshes or
    includes) is loaded by its path relative to ``at``, where the notebook will be written
    (None: the current folder).

    Raises
    ------
    ParameterError
        When a parameter has no value: the notebook's checks, comparison with Newton–Euler and
        simulation are numeric, and would fail cell by cell.
    """
    missing = [p.name for p in model.parameters if p.value is None]
    if missing:
        raise ParameterError(model.source, "parameters",
                             "the notebook's numeric cells need a value for "
                             + ", ".join(missing))
    chart = model.nq > model.dof  # q (NQ) and v (NV) differ: no textbook form
    small = not chart and model.dof <= TEXTBOOK_MAX_DOF and _teaching_sized(model)
    source = embedded_source(description, scene, at)
    context = {
        "name": model.name, "nq": model.nq, "dof": model.dof, "chart": chart, "check": check,
        "chart_joints": chart_joint_names(model),
        "textbook_max_dof": TEXTBOOK_MAX_DOF, "textbook_max_operations": TEXTBOOK_MAX_OPERATIONS,
        "source": source,
    }
    cells = [_cell(block, context) for block in cell_blocks(source, chart, small, check)]
    nb = v4.new_notebook(cells=cells, metadata={
        "kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"},
        "language_info": {"name": "python"},
    })
    for k, cell in enumerate(nb.cells):  # deterministic ids (nbformat makes random ones)
        cell["id"] = f"cell-{k:02d}"
    return nb


#: The template of the notebook's cells: one block per cell.
CELLS_TEMPLATE = "notebook/cells.jinja"

#: The sections of the textbook derivation, for a teaching-sized model.
_TEXTBOOK = ("jacobians", "energy", "mass_matrix", "christoffel", "coriolis", "gravity")
#: The linear-in-the-parameters sections, for the same models.
_REGRESSOR = ("regressor", "base_parameters", "slotine_li")


def cell_blocks(source: EmbeddedSource, chart: bool, small: bool, check: bool) -> list[str]:
    """The notebook's cells, in order, as the names of their blocks in :data:`CELLS_TEMPLATE`:
    a ``<section>_text`` block is a markdown cell, a ``<section>_code`` block a code cell."""
    def section(*names: str) -> list[str]:
        return [f"{name}_{part}" for name in names for part in ("text", "code")]

    blocks = ["chart_intro_text" if chart else "intro_text", "robot_text"]
    if source.description is not None:
        blocks.append("description_code")
    if source.scene is not None:
        blocks.append("scene_code")
    blocks.append("setup_code")
    blocks += section(*_TEXTBOOK) if small else section("program")
    blocks += section("equations")
    if small:
        blocks += section(*_REGRESSOR)
    if not check:
        blocks.append("no_check_text")
    else:
        blocks += section("chart_verify" if chart else "verify")
    blocks += section("pinocchio" if chart else "newton_euler")
    return blocks + section("simulation")


def _cell(block: str, context: dict) -> nbformat.NotebookNode:
    """The cell of ``block`` rendered with ``context``, without leading or trailing blank
    lines."""
    text = render_block(CELLS_TEMPLATE, block, **context).strip()
    if block.endswith("_text"):
        return v4.new_markdown_cell(text)
    return v4.new_code_cell(text)


def write_notebook(nb: nbformat.NotebookNode, path: Path) -> Path:
    """Write ``nb`` to ``path`` atomically (a temporary file in the same folder, then
    :func:`os.replace`): a reader never sees half a notebook."""
    path = Path(path)
    nbformat.validate(nb)
    text = nbformat.writes(nb)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            handle.write(text)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    return path


__all__ = ["CELLS_TEMPLATE", "build_notebook", "cell_blocks", "text_literal", "write_notebook"]
