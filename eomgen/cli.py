"""Command line interface: ``eomgen verify``, ``generate``, ``notebook``, ``teach`` (and
``bench``, ``simulate`` from :mod:`eomgen.analysis.commands`; ``excite``, ``identify`` from
:mod:`eomgen.identification.commands`).

Exit codes: 0 success, 1 a verification check failed, 2 bad input (one line on stderr naming the
file, the element and the problem; a traceback only with ``--debug``), 130 interrupted (SIGINT,
Ctrl-C) and 143 terminated (SIGTERM), each with the one line ``eomgen: interrupted``.

Every command that writes checks first that its output can be written (:mod:`eomgen.output`),
so that a bad ``-o`` is one error line before minutes of work. Progress goes to stderr through
one :class:`eomgen.progress.Progress` (``--quiet`` on every command silences it).
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import signal
import sys
import threading
import time
import warnings
from pathlib import Path

import click

from . import __version__
from .errors import EomgenError, GenerationError, one_line
from .progress import end_line


def _default_description() -> Path:
    from .robots import example_path

    return example_path("planar_2link")


class _Terminated(KeyboardInterrupt):
    """SIGTERM, raised wherever the program is (as SIGINT raises KeyboardInterrupt), so that
    the same cleanups run: a generation in progress leaves the previous output untouched."""


def _raise_terminated(signum, frame):
    raise _Terminated()


@contextlib.contextmanager
def _sigterm_raises():
    """Within the block, SIGTERM raises :class:`_Terminated` (main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def _handle_errors(command):
    """Turn EomgenError into one line on stderr and exit code 2 (traceback with --debug), and
    an interrupt (SIGINT, SIGTERM) into ``eomgen: interrupted`` and exit code 130 or 143."""

    @functools.wraps(command)
    def wrapper(*args, debug: bool = False, **kwargs):
        def show_warning(message, category, filename, lineno, file=None, line=None):
            end_line()
            click.echo(f"eomgen: warning: {message}", err=True)

        warnings.showwarning = show_warning
        try:
            with _sigterm_raises():
                return command(*args, **kwargs)
        except EomgenError as exc:
            end_line()
            if debug:
                raise
            click.echo(f"eomgen: error: {exc}", err=True)
            sys.exit(2)
        except KeyboardInterrupt as exc:
            end_line()
            if debug:
                raise
            click.echo("eomgen: interrupted", err=True)
            sys.exit(128 + (signal.SIGTERM if isinstance(exc, _Terminated) else signal.SIGINT))

    return click.option("--debug", is_flag=True, help="Show a traceback on errors.")(wrapper)


@contextlib.contextmanager
def _recorded_warnings():
    """Within the block, warnings are shown as usual and their messages collected in the list
    yielded (a cached run prints them again)."""
    notices: list[str] = []
    shown = warnings.showwarning

    def record(message, *args, **kwargs):
        notices.append(one_line(str(message)))
        shown(message, *args, **kwargs)

    warnings.showwarning = record
    try:
        yield notices
    finally:
        warnings.showwarning = shown


def _answer_from_cache(request, outdir: Path, quiet: bool, cache_dir: Path | None) -> bool:
    """Write the files of a cached ``eomgen generate`` run and list them, as the run did;
    False when the cache holds no (valid) entry. Imports neither SymPy nor the parsers."""
    from .cache import Cache
    from .output import write_atomically

    entry = Cache(cache_dir).get(request.key)
    if entry is None:
        return False
    for notice in entry.notices:
        click.echo(f"eomgen: warning: {notice}", err=True)
    if not quiet:
        click.echo(f"eomgen: using cached result (key {request.key[:16]}…)", err=True)
    for path in write_atomically(entry.files, outdir):
        click.echo(str(path))
    return True


description_argument = click.argument(
    "description", required=False, type=click.Path(dir_okay=False, path_type=Path))
strict_option = click.option(
    "--strict", is_flag=True,
    help="Refuse inertias that break the triangle inequality, URDF <mimic> joints and a URDF "
         "root that looks like a floating base, instead of warning (only about what a "
         "--scene keeps).")


def _load(description: Path | None, strict: bool, scene=None, snap: bool = True):
    """The whole model; warns (refuses under ``strict``) only about what ``scene`` (a loaded
    :class:`eomgen.scene.Scene`, applied by the caller) keeps. ``snap=False`` keeps the
    description's floats exactly (``--no-snap``)."""
    from .reduction import load_for_scene

    return load_for_scene(description or _default_description(), scene, strict, snap=snap)


# Options and helpers shared by the commands (``bench`` and ``simulate`` take them too).

quiet_option = click.option("--quiet", is_flag=True,
                            help="No progress on stderr (stage lines in a log, an updating "
                                 "line or bar on a terminal).")


def scene_option(help: str = "Scene file (YAML, docs/scenes.md): reduce the robot to what the "
                             "scene moves first (e.g. examples/scenes/panda_two_joints.yaml)."):
    return click.option("--scene", "scene_path", default=None,
                        type=click.Path(dir_okay=False, path_type=Path), help=help)


def output_folder_option(default: str):
    """``-o/--output`` for a folder; whether it can be written is checked by the command
    (:func:`eomgen.output.check_output_folder`: one error line, not click's usage text)."""
    return click.option("-o", "--output", "outdir", default=default, show_default=True,
                        type=click.Path(path_type=Path), help="Output folder.")


def _functions_option(text: str | None) -> tuple[str, ...] | None:
    """The functions ``--outputs`` names (None when not given), or a one-line error."""
    if text is None:
        return None
    from .outputs import select

    try:
        return select([n.strip() for n in text.split(",") if n.strip()])
    except ValueError as exc:
        raise GenerationError(f"--outputs: {exc}") from None


def _load_reduced(description: Path | None, scene_path: Path | None, strict: bool):
    """``(model, report)``: the description reduced by the scene file (report None without
    one). The scene is read first, so that warnings concern only what it keeps."""
    if scene_path is None:
        return _load(description, strict), None
    from .reduction import apply_scene
    from .scene import load_scene

    scene = load_scene(scene_path, strict=strict)
    return apply_scene(_load(description, strict, scene), scene)


def _progress(quiet: bool):
    from .progress import Progress

    return Progress(quiet)


@click.group(context_settings={"help_option_names": ["-h", "--help"]},
             invoke_without_command=True)
@click.version_option(__version__, prog_name="eomgen")
@click.pass_context
def main(ctx):
    """eomgen: symbolic equations of motion M(q) q̈ + C(q, q̇) q̇ + g(q) = τ for robots.

    \b
    Examples:
      eomgen generate                        # code for the bundled planar 2-link arm
      eomgen generate ur5.urdf --backend numpy,casadi -o build/ur5
      eomgen verify                          # check the bundled arm against Newton-Euler
      eomgen verify robot.urdf --samples 50
    """
    if ctx.invoked_subcommand is None:  # plain ``eomgen``: the help, and success
        click.echo(ctx.get_help())
        ctx.exit(0)


@main.command()
@description_argument
@click.option("--samples", default=20, show_default=True, help="Random states for numeric checks.")
@click.option("--seed", default=0, show_default=True, help="Seed of the random states.")
@click.option("--tolerance", default=1e-9, show_default=True, help="Relative tolerance.")
@scene_option()
@quiet_option
@strict_option
@_handle_errors
def verify(description, samples, seed, tolerance, scene_path, quiet, strict):
    """Derive DESCRIPTION's dynamics and check them against Newton–Euler.

    DESCRIPTION is a URDF, DH-table YAML or eomgen YAML file (default: the bundled planar
    2-link arm). Checks: M symmetric positive definite, Ṁ − 2C skew-symmetric, g, the columns of
    M and the whole equation against the numeric recursive Newton–Euler algorithm.

    \b
    Examples:
      eomgen verify
      eomgen verify ur5.urdf --samples 100 --seed 3
      eomgen verify panda.urdf --scene examples/scenes/panda_two_joints.yaml
    """
    from .dynamics import ALL_OUTPUTS, derive
    from .errors import VerificationError
    from .progress import plural
    from .verify import verify as run_verify

    if samples < 1:
        raise VerificationError(f"--samples must be at least 1, got {samples}")
    progress = _progress(quiet)
    model, _ = _load_reduced(description, scene_path, strict)
    start = time.perf_counter()
    progress(f"deriving M, C, g and tau of {model.name} ({plural(model.dof, 'joint')})")
    dynamics = derive(model, outputs=ALL_OUTPUTS)
    seconds = time.perf_counter() - start
    progress(f"checking at {plural(samples, 'random state')}")
    report = run_verify(dynamics, samples=samples, seed=seed, tolerance=tolerance)
    progress.clear()
    click.echo(f"derived {model.name} ({plural(model.dof, 'joint')}: "
               f"{', '.join(model.joint_names)}) in {seconds:.2f} s")
    click.echo(report.format())
    sys.exit(0 if report.passed else 1)


class _BackendOption(click.Option):
    """``--backend``, whose help lists the registered backends (looked up when help is shown,
    so that ``eomgen`` starts without importing the code generators)."""

    def get_help_record(self, ctx):
        from .codegen import available_backends

        template = self.help
        self.help = template.format(backends=", ".join(available_backends()))
        try:
            return super().get_help_record(ctx)
        finally:
            self.help = template


@main.command()
@description_argument
@click.option("--backend", "backends", default="all", show_default=True, cls=_BackendOption,
              help="Comma-separated backends among {backends}; or all.")
@output_folder_option("eomgen_output")
@click.option("--symbolic", default=None,
              help="Comma-separated parameters to keep symbolic (default: all the description "
                   "declares; 'none' for none). The others take their values.")
@quiet_option
@scene_option("Scene file (YAML, docs/scenes.md): the part that moves, locked joints, "
              "payloads, gravity, outputs. Writes <robot>_scene_report.md too.")
@click.option("--explain", is_flag=True,
              help="Print what was merged, locked and dropped, and derive the whole "
                   "description too to compare operation counts and times.")
@click.option("--no-cache", is_flag=True,
              help="Derive afresh: neither read nor write the derivation cache.")
@click.option("--cache-dir", default=None, type=click.Path(file_okay=False, path_type=Path),
              help="Derivation cache folder (default: $EOMGEN_CACHE_DIR, else "
                   "$XDG_CACHE_HOME/eomgen, else ~/.cache/eomgen).")
@click.option("--no-snap", is_flag=True,
              help="Keep rotation and axis entries exactly as the description's floats give "
                   "them (default: entries within 1e-11 of 0 or ±1 are made exact).")
@click.option("--outputs", default=None,
              help="Comma-separated functions to export, by name or symbol (default: M, C, g, "
                   "tau and forward dynamics; docs/outputs.md lists the others, e.g. Y). "
                   "Replaces a scene's outputs.")
@strict_option
@_handle_errors
def generate(description, backends, outdir, symbolic, quiet, scene_path, explain, no_cache,
             cache_dir, no_snap, outputs, strict):
    """Generate code and a derivation for DESCRIPTION (default: the bundled planar 2-link arm).

    Writes <robot>_numpy.py (NumPy, single states and batches), <robot>_casadi.py (CasADi
    functions), <robot>_casadi.c/.h (C through CasADi, plus a .so when a C compiler is found) and
    <robot>.tex (the derivation) into OUTPUT, all files or none. A request made before (same
    file bytes, options and eomgen) is answered from the derivation cache.

    \b
    Examples:
      eomgen generate
      eomgen generate robot.urdf --backend numpy -o build/
      eomgen generate eomgen/robots/planar_2link.yaml --symbolic m2,g
      eomgen generate talos_reduced.urdf --scene examples/scenes/talos_left_arm.yaml --explain
    """
    from .output import check_output_folder

    check_output_folder(outdir)
    functions = _functions_option(outputs)
    progress = _progress(quiet)
    request = None
    if not no_cache:
        from .cache import command_request

        request = command_request(description or _default_description(),
                                  click.get_current_context().params)
        if request is not None and _answer_from_cache(request, outdir, quiet, cache_dir):
            return
    from .codegen.generate import generate as run_generate

    with _recorded_warnings() as notices:
        scene = None
        if scene_path is not None:
            from .scene import load_scene

            scene = load_scene(scene_path, strict=strict)
            if functions is not None:
                scene = dataclasses.replace(scene, outputs=functions)
        model = _load(description, strict, scene, snap=not no_snap)
    cache = dataclasses.replace(request, notices=notices) if request else not no_cache
    names = None
    if symbolic is not None:
        names = [] if symbolic.strip().lower() == "none" else [
            n.strip() for n in symbolic.split(",") if n.strip()]
    if scene_path is not None or explain:
        from .codegen.scene_generate import generate_scene

        paths, produced = generate_scene(model, scene, outdir, backends, names, progress,
                                         explain, cache=cache, cache_dir=cache_dir)
        progress.clear()
        if explain:
            click.echo(produced.markdown)
    else:
        paths = run_generate(model, outdir, backends, names, progress, functions, cache=cache,
                             cache_dir=cache_dir)
        progress.clear()
    for path in paths:
        click.echo(str(path))


@main.command()
@description_argument
@click.option("-o", "--output", "output", default=None, type=click.Path(path_type=Path),
              help="Notebook file to write (default: <robot>_derivation.ipynb).")
@scene_option()
@quiet_option
@strict_option
@_handle_errors
def notebook(description, output, scene_path, quiet, strict):
    """Write a Jupyter notebook deriving DESCRIPTION's equations of motion step by step.

    The notebook (saved without outputs) loads the robot, derives positions, Jacobians,
    energies, M, the Christoffel symbols, C and g (textbook form for at most 3 joints), checks
    them, compares them with Newton–Euler and simulates the robot.

    \b
    Examples:
      eomgen notebook                        # the bundled planar 2-link arm
      eomgen notebook ur5.urdf -o ur5.ipynb
      eomgen notebook panda.urdf --scene examples/scenes/panda_two_joints.yaml
    """
    from .notebook import build_notebook, write_notebook
    from .output import check_output_file

    if output is not None:
        check_output_file(output)
    progress = _progress(quiet)
    model, _ = _load_reduced(description, scene_path, strict)
    path = output or Path(f"{model.name}_derivation.ipynb")
    if output is None:
        check_output_file(path)
    progress(f"building the notebook of {model.name}")
    nb = build_notebook(model, description, scene=scene_path)
    progress.clear()
    click.echo(str(write_notebook(nb, path)))


@main.command()
@description_argument
@click.option("--format", "formats", default=None,
              help="Comma-separated handout formats among pdf, html, md, tex; or all. "
                   "[default: pdf; html, with a note, when pdflatex is not installed]")
@output_folder_option("eomgen_handout")
@scene_option("Scene file (YAML, docs/scenes.md): derive only what it moves, e.g. two "
              "joints of a real arm (examples/scenes/panda_two_joints.yaml).")
@click.option("--no-check", is_flag=True,
              help="Leave out the numeric verification (the handout says so).")
@quiet_option
@strict_option
@_handle_errors
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
    import shutil

    from .output import check_output_folder
    from .teach import parse_formats, write_handout

    progress = _progress(quiet)
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
    model, report = _load_reduced(description, scene_path, strict)
    paths = write_handout(model, outdir, chosen, progress, check=not no_check, scene=report)
    progress.clear()
    for path in paths:
        click.echo(str(path))


# ``eomgen bench`` and ``eomgen simulate`` (eomgen/analysis/commands.py), with this module's
# error handling, DESCRIPTION argument, --strict and loading.
from .analysis.commands import add_commands as _add_analysis_commands  # noqa: E402

_add_analysis_commands(main, _handle_errors, description_argument, strict_option,
                       _load_reduced)

# ``eomgen excite`` and ``eomgen identify`` (eomgen/identification/commands.py).
from .identification.commands import add_commands as _add_identification_commands  # noqa: E402

_add_identification_commands(main, _handle_errors, strict_option, quiet_option, scene_option,
                             _load_reduced)


if __name__ == "__main__":  # pragma: no cover
    main()
