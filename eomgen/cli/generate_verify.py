"""``eomgen generate`` (code and a derivation, answered from the derivation cache when it can)
and ``eomgen verify`` (the derived dynamics against Newton–Euler).

SymPy, the parsers and the code generators are imported inside the commands, after the cache
is asked: a cached ``eomgen generate`` imports neither SymPy nor the parsers.
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

import click

from ..errors import GenerationError, VerificationError
from ..common.output import check_output_folder, checked_stem, python_module_name, write_atomically
from ..common.progress import HEARTBEAT_SECONDS, Progress, plural
from .handling import handle_errors, recorded_warnings
from .loading import command_params, default_description, load, load_reduced
from .options import (description_argument, output_folder_option, quiet_option, scene_option,
                      strict_option)


@click.command()
@description_argument()
@click.option("--samples", default=20, show_default=True, help="Random states for numeric checks.")
@click.option("--seed", default=0, show_default=True, help="Seed of the random states.")
@click.option("--tolerance", default=1e-9, show_default=True, help="Relative tolerance.")
@scene_option()
@quiet_option()
@strict_option
@handle_errors
def verify(description, samples, seed, tolerance, scene_path, quiet, strict):
    """Derive DESCRIPTION's dynamics and check them against Newton–Euler.

    DESCRIPTION is a URDF, DH-table YAML or eomgen YAML file, or a bundled example's name
    (default: the bundled planar 2-link arm). Checks: M symmetric positive definite, Ṁ − 2C
    skew-symmetric, g, the columns of M and the whole equation against the numeric recursive
    Newton–Euler algorithm.

    \b
    Examples:
      eomgen verify
      eomgen verify ur5.urdf --samples 100 --seed 3
      eomgen verify panda.urdf --scene examples/scenes/panda_two_joints.yaml
    """
    # SymPy: imported when the command runs, not when the CLI starts
    from ..dynamics import ALL_OUTPUTS, derive
    from ..verify import verify as run_verify

    if samples < 1:
        raise VerificationError(f"--samples must be at least 1, got {samples}")
    progress = Progress(quiet, heartbeat=HEARTBEAT_SECONDS)
    model, _ = load_reduced(description, scene_path, strict)
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


class BackendOption(click.Option):
    """``--backend``, whose help lists the registered backends (looked up when help is shown,
    so that ``eomgen`` starts without importing the code generators)."""

    def get_help_record(self, ctx):
        from ..codegen import available_backends  # SymPy: only when the help is shown

        template = self.help
        self.help = template.format(backends=", ".join(available_backends()))
        try:
            return super().get_help_record(ctx)
        finally:
            self.help = template


class BackendListingCommand(click.Command):
    """A command whose help ends its description with the registered backends, one line each
    (:func:`eomgen.codegen.available_backends`, looked up when help is shown), so that a new
    backend is listed without editing the help."""

    def format_help_text(self, ctx, formatter):
        super().format_help_text(ctx, formatter)
        from ..codegen import available_backends  # SymPy: only when the help is shown

        with formatter.section("Backends (--backend; all by default)"):
            formatter.write_dl([(name, backend.description)
                                for name, backend in available_backends().items()])


def functions_option(text: str | None) -> tuple[str, ...] | None:
    """The functions ``--outputs`` names (None when not given), or a one-line error."""
    if text is None:
        return None
    from ..outputs import select  # start-up time: only when --outputs is given

    try:
        return select([n.strip() for n in text.split(",") if n.strip()])
    except ValueError as exc:
        raise GenerationError(f"--outputs: {exc}") from None


def import_hint(paths: list[Path], outdir: Path, stem_given: bool) -> str | None:
    """The line saying how to import the Python modules among ``paths`` (None when there are
    none: LaTeX or C only): every ``.py`` file and extension module
    (:func:`eomgen.common.output.python_module_name`; no C library)."""
    modules = {python_module_name(p.name) for p in paths} - {None}
    modules = sorted(modules, key=lambda m: (not m.endswith("_numpy"), m))
    if not modules:
        return None
    also = f" (also {', '.join(modules[1:])})" if len(modules) > 1 else ""
    rename = "" if stem_given else "; --name STEM names them STEM_*"
    return (f"eomgen: to import, put the folder on the path, sys.path.insert(0, "
            f"{str(outdir)!r}), then import {modules[0]}{also}{rename}")


def answer_from_cache(request, outdir: Path, quiet: bool, cache_dir: Path | None
                      ) -> list[Path] | None:
    """Write the files of a cached ``eomgen generate`` run and list them, as the run did, and
    return their paths; None when the cache holds no (valid) entry. Imports neither SymPy nor
    the parsers."""
    from ..cache import Cache  # start-up time (certifi, ~0.15 s): only when asked

    entry = Cache(cache_dir).get(request.key)
    if entry is None:
        return None
    for notice in entry.notices:
        click.echo(f"eomgen: warning: {notice}", err=True)
    if not quiet:
        click.echo(f"eomgen: using cached result (key {request.key[:16]}…)", err=True)
    paths = write_atomically(entry.files, outdir)
    for path in paths:
        click.echo(str(path))
    return paths


@click.command(cls=BackendListingCommand)
@description_argument()
@click.option("--backend", "backends", default="all", show_default=True, cls=BackendOption,
              help="Comma-separated backends among {backends}; or all.")
@output_folder_option("eomgen_output")
@click.option("--symbolic", default=None,
              help="Comma-separated parameters to keep symbolic (default: all the description "
                   "declares; 'none' for none). The others take their values.")
@quiet_option()
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
@click.option("--name", "name", default=None, metavar="STEM",
              help="Name the files and modules STEM_numpy.py, STEM_casadi.py, ... (a Python "
                   "identifier; default: from the robot's name in the description).")
@click.option("--no-snap", is_flag=True,
              help="Keep rotation and axis entries exactly as the description's floats give "
                   "them (default: entries within 1e-11 of 0 or ±1, and angles within 1e-12 "
                   "of a multiple of pi/12, are made exact).")
@click.option("--outputs", default=None,
              help="Comma-separated functions to export, by name or symbol (default: M, C, g, "
                   "tau and forward dynamics; docs/outputs.md lists the others, e.g. Y). "
                   "Replaces a scene's outputs.")
@click.option("--jobs", default=None, type=click.IntRange(min=1), metavar="N",
              help="Compilers run at a time when building the fast module, whose long kernels "
                   "compile as units of their own (default: $EOMGEN_JOBS, else the cores).")
@strict_option
@handle_errors
def generate(description, backends, outdir, symbolic, quiet, scene_path, explain, no_cache,
             cache_dir, name, no_snap, outputs, jobs, strict):
    """Generate code and a derivation for DESCRIPTION (default: the bundled planar 2-link arm).

    Writes the files of each backend (listed below) into OUTPUT, named <robot>_<backend>
    (<robot>_numpy.py, <robot>_casadi.c, <robot>.tex, ...), all files or none. A request made
    before (same file bytes, options and eomgen) is answered from the derivation cache.

    \b
    Examples:
      eomgen generate
      eomgen generate robot.urdf --backend numpy -o build/
      eomgen generate eomgen/robots/planar_2link.yaml --symbolic m2,g
      eomgen generate talos_reduced.urdf --scene examples/scenes/talos_left_arm.yaml --explain
    """
    checked_stem(name)
    check_output_folder(outdir)
    functions = functions_option(outputs)
    progress = Progress(quiet, heartbeat=HEARTBEAT_SECONDS)
    request = None
    if not no_cache:
        from ..cache import command_request  # start-up time (certifi): only when asked

        request = command_request(description or default_description(), command_params())
        paths = None if request is None else answer_from_cache(request, outdir, quiet,
                                                                 cache_dir)
        if paths is not None:
            say_how_to_import(paths, outdir, name, quiet)
            return
    # SymPy and the code generators: only when the cache did not answer
    from ..codegen.generate import generate as run_generate
    from ..common.compiler import jobs_set

    with recorded_warnings() as notices:
        scene = None
        if scene_path is not None:
            from ..scene import load_scene  # YAML and SymPy, as above

            scene = load_scene(scene_path, strict=strict)
            if functions is not None:
                scene = dataclasses.replace(scene, outputs=functions)
        model = load(description, strict, scene, snap=not no_snap)
    cache = dataclasses.replace(request, notices=notices) if request else not no_cache
    names = None
    if symbolic is not None:
        names = [] if symbolic.strip().lower() == "none" else [
            n.strip() for n in symbolic.split(",") if n.strip()]
    if scene_path is not None or explain:
        from ..codegen.scene_generate import generate_scene  # SymPy, as above

        with jobs_set(jobs):
            paths, produced = generate_scene(model, scene, outdir, backends, names, progress,
                                             explain, cache=cache, cache_dir=cache_dir,
                                             stem=name)
        progress.clear()
        if explain:
            click.echo(produced.markdown)
    else:
        with jobs_set(jobs):
            paths = run_generate(model, outdir, backends, names, progress, functions,
                                 cache=cache, cache_dir=cache_dir, stem=name)
        progress.clear()
    for path in paths:
        click.echo(str(path))
    say_how_to_import(paths, outdir, name, quiet)


def say_how_to_import(paths: list[Path], outdir: Path, name: str | None, quiet: bool) -> None:
    """One line on stderr (not under ``--quiet``): how to import the modules written."""
    hint = import_hint(paths, outdir, name is not None)
    if hint and not quiet:
        click.echo(hint, err=True)
