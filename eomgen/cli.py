"""Command line interface: ``eomgen verify``, ``eomgen generate``.

Exit codes: 0 success, 1 a verification check failed, 2 bad input (one line on stderr naming the
file, the element and the problem; a traceback only with ``--debug``).
"""

from __future__ import annotations

import functools
import sys
import time
import warnings
from pathlib import Path

import click

from . import __version__
from .errors import EomgenError


def _default_description() -> Path:
    from .robots import example_path

    return example_path("planar_2link")


def _handle_errors(command):
    """Turn EomgenError into one line on stderr and exit code 2 (traceback with --debug)."""

    @functools.wraps(command)
    def wrapper(*args, debug: bool = False, **kwargs):
        def show_warning(message, category, filename, lineno, file=None, line=None):
            click.echo(f"eomgen: warning: {message}", err=True)

        warnings.showwarning = show_warning
        try:
            return command(*args, **kwargs)
        except EomgenError as exc:
            if debug:
                raise
            click.echo(f"eomgen: error: {exc}", err=True)
            sys.exit(2)

    return click.option("--debug", is_flag=True, help="Show a traceback on errors.")(wrapper)


description_argument = click.argument(
    "description", required=False, type=click.Path(dir_okay=False, path_type=Path))
strict_option = click.option(
    "--strict", is_flag=True,
    help="Refuse inertias that break the triangle inequality and URDF <mimic> joints "
         "instead of warning.")


def _load(description: Path | None, strict: bool):
    from .parsers import load

    return load(description or _default_description(), strict=strict)


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="eomgen")
def main():
    """eomgen: symbolic equations of motion M(q) q̈ + C(q, q̇) q̇ + g(q) = τ for robots.

    \b
    Examples:
      eomgen generate                        # code for the bundled planar 2-link arm
      eomgen generate ur5.urdf --backend numpy,casadi -o build/ur5
      eomgen verify                          # check the bundled arm against Newton-Euler
      eomgen verify robot.urdf --samples 50
    """


@main.command()
@description_argument
@click.option("--samples", default=20, show_default=True, help="Random states for numeric checks.")
@click.option("--seed", default=0, show_default=True, help="Seed of the random states.")
@click.option("--tolerance", default=1e-9, show_default=True, help="Relative tolerance.")
@strict_option
@_handle_errors
def verify(description, samples, seed, tolerance, strict):
    """Derive DESCRIPTION's dynamics and check them against Newton–Euler.

    DESCRIPTION is a URDF, DH-table YAML or eomgen YAML file (default: the bundled planar
    2-link arm). Checks: M symmetric positive definite, Ṁ − 2C skew-symmetric, g, the columns of
    M and the whole equation against the numeric recursive Newton–Euler algorithm.

    \b
    Examples:
      eomgen verify
      eomgen verify ur5.urdf --samples 100 --seed 3
    """
    from .dynamics import ALL_OUTPUTS, derive
    from .verify import verify as run_verify

    model = _load(description, strict)
    start = time.perf_counter()
    dynamics = derive(model, outputs=ALL_OUTPUTS)
    click.echo(f"derived {model.name} ({model.dof} joints: {', '.join(model.joint_names)}) "
               f"in {time.perf_counter() - start:.2f} s")
    report = run_verify(dynamics, samples=samples, seed=seed, tolerance=tolerance)
    click.echo(report.format())
    sys.exit(0 if report.passed else 1)


@main.command()
@description_argument
@click.option("--backend", "backends", default="all", show_default=True,
              help="Comma-separated backends among numpy, casadi, c, latex; or all.")
@click.option("-o", "--output", "outdir", default="eomgen_output", show_default=True,
              type=click.Path(file_okay=False, path_type=Path), help="Output folder.")
@click.option("--symbolic", default=None,
              help="Comma-separated parameters to keep symbolic (default: all the description "
                   "declares; 'none' for none). The others take their values.")
@click.option("--quiet", is_flag=True, help="No progress lines.")
@strict_option
@_handle_errors
def generate(description, backends, outdir, symbolic, quiet, strict):
    """Generate code and a derivation for DESCRIPTION (default: the bundled planar 2-link arm).

    Writes <robot>_numpy.py (NumPy, single states and batches), <robot>_casadi.py (CasADi
    functions), <robot>_casadi.c/.h (C through CasADi, plus a .so when a C compiler is found) and
    <robot>.tex (the derivation) into OUTPUT, all files or none.

    \b
    Examples:
      eomgen generate
      eomgen generate robot.urdf --backend numpy -o build/
      eomgen generate eomgen/robots/planar_2link.yaml --symbolic m2,g
    """
    from .codegen.generate import generate as run_generate

    model = _load(description, strict)
    names = None
    if symbolic is not None:
        names = [] if symbolic.strip().lower() == "none" else [
            n.strip() for n in symbolic.split(",") if n.strip()]

    def progress(line: str) -> None:
        if not quiet:
            click.echo(f"eomgen: {line}", err=True)

    paths = run_generate(model, outdir, backends, names, progress)
    for path in paths:
        click.echo(str(path))


if __name__ == "__main__":  # pragma: no cover
    main()
