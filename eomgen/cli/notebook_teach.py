"""``eomgen notebook`` (a Jupyter notebook deriving the equations step by step) and
``eomgen teach`` (a handout for students): the command-line side of :mod:`eomgen.teach.notebook` and
:mod:`eomgen.teach`, imported when a command runs (they import SymPy).
"""

from __future__ import annotations

import contextlib
import shutil
from pathlib import Path

import click

from ..errors import EomgenError, GenerationError
from ..common.output import check_output_file, check_output_folder
from ..common.progress import HEARTBEAT_SECONDS, Progress
from .handling import handle_errors
from .loading import load_reduced
from .options import (description_argument, output_file_option, output_folder_option,
                      quiet_option, scene_option, strict_option)


@contextlib.contextmanager
def unexpected_errors(what: str):
    """Within the block, an exception that is not an :class:`~eomgen.errors.EomgenError` (a
    defect of eomgen, not of the description) becomes a :class:`GenerationError` naming
    ``what`` and the exception in one line, so that the command ends on the CLI's error line
    (exit 2) rather than a traceback; ``--debug`` shows the traceback (the original is
    chained)."""
    try:
        yield
    except EomgenError:
        raise
    except OSError as exc:  # the machine's (a full disk), not eomgen's
        raise GenerationError(f"{what} failed: {exc}") from exc
    except Exception as exc:  # noqa: BLE001 (reported, never hidden: see the docstring)
        raise GenerationError(
            f"{what} failed unexpectedly ({type(exc).__name__}: {exc}); this is a defect of "
            "eomgen: please report it with the description (--debug shows the traceback)"
        ) from exc


@click.command()
@description_argument()
@output_file_option("Notebook file to write (default: <robot>_derivation.ipynb).")
@scene_option()
@click.option("--no-check", is_flag=True,
              help="Leave out the checks (eomgen.verify, Mdot - 2C skew-symmetric, the "
                   "asserted comparisons); the notebook says so.")
@quiet_option()
@strict_option
@handle_errors
def notebook(description, output, scene_path, no_check, quiet, strict):
    """Write a Jupyter notebook deriving DESCRIPTION's equations of motion step by step.

    The notebook (saved without outputs) holds the description's text, so it runs wherever
    it is copied; it loads the robot, derives positions, Jacobians, energies, M, the
    Christoffel symbols, C and g (textbook form for at most 3 joints), checks them, compares
    them with Newton–Euler and simulates the robot. Run it with the notebook extra (pip
    install 'eomgen[notebook]'): jupyter lab FILE, or headless jupyter nbconvert --to notebook
    --execute FILE.

    \b
    Examples:
      eomgen notebook                        # the bundled planar 2-link arm
      eomgen notebook ur5.urdf -o ur5.ipynb
      eomgen notebook panda.urdf --scene examples/scenes/panda_two_joints.yaml
    """
    from ..teach.notebook import build_notebook, write_notebook  # SymPy: when the command runs

    if output is not None:
        check_output_file(output)
    progress = Progress(quiet, heartbeat=HEARTBEAT_SECONDS)
    model, _ = load_reduced(description, scene_path, strict)
    path = output or Path(f"{model.name}_derivation.ipynb")
    if output is None:
        check_output_file(path)
    progress(f"building the notebook of {model.name}")
    with unexpected_errors(f"building the notebook of {model.name}"):
        nb = build_notebook(model, description, scene=scene_path, check=not no_check,
                            at=path)
    progress.clear()
    click.echo(str(write_notebook(nb, path)))


@click.command()
@description_argument()
@click.option("--format", "formats", default=None,
              help="Comma-separated handout formats among pdf, html, md, tex; or all. "
                   "[default: pdf; html, with a note, when pdflatex is not installed]")
@output_folder_option("eomgen_handout")
@scene_option("Scene file (YAML, docs/scenes.md): derive only what it moves, e.g. two "
              "joints of a real arm (examples/scenes/panda_two_joints.yaml).")
@click.option("--no-check", is_flag=True,
              help="Leave out the checks: the numeric verification (the handout says "
                   "so) and those of what it writes with named factors.")
@quiet_option()
@strict_option
@handle_errors
def teach(description, formats, outdir, scene_path, no_check, quiet, strict):
    """Write a handout deriving DESCRIPTION's equations of motion for students.

    The robot (tables and a kinematic sketch), the Lagrangian derivation step by step
    (positions, velocities, kinetic and potential energy, M, Christoffel symbols and C, g,
    the equations of motion; named subexpressions for models too large to print expanded) and
    the verified properties with their numbers. Formats: pdf (through pdflatex), html (one
    self-contained file, math as MathML), md (Markdown with $...$ math, plus the sketch as SVG),
    tex (LaTeX source, plus the sketch as PDF). All files or none are written. The pdf format
    needs pdflatex (TeX Live); without it the default is html, and asking for pdf is an error.

    \b
    Examples:
      eomgen teach                                  # the bundled planar 2-link arm, PDF
      eomgen teach robot.urdf --format html,md -o handouts/
      eomgen teach panda.urdf --scene examples/scenes/panda_two_joints.yaml
    """
    from ..teach import parse_formats, write_handout  # SymPy: when the command runs

    progress = Progress(quiet, heartbeat=HEARTBEAT_SECONDS)
    have_pdflatex = shutil.which("pdflatex") is not None
    if formats is None:
        chosen = ["pdf"] if have_pdflatex else ["html"]
        if not have_pdflatex:
            progress.note("pdflatex not found: writing the html handout instead of the pdf "
                          "(install TeX Live for pdf, or choose with --format)")
    else:
        chosen = parse_formats(formats)
        if "pdf" in chosen and not have_pdflatex:
            raise GenerationError("--format pdf needs pdflatex, which is not installed (TeX "
                                  "Live: apt install texlive-latex-base); choose html, md or tex")
    check_output_folder(outdir)
    model, report = load_reduced(description, scene_path, strict)
    with unexpected_errors(f"writing the handout of {model.name}"):
        paths = write_handout(model, outdir, chosen, progress, check=not no_check,
                              scene=report)
    progress.clear()
    for path in paths:
        click.echo(str(path))
