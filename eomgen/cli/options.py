"""The arguments and options several ``eomgen`` commands take, declared once.

Each is a click decorator (or a function making one, where commands differ in a default or a
help text): the DESCRIPTION argument (a file, or a bundled example's name; with it
``--mimic``), ``--scene``, ``--quiet``, ``--strict`` and ``-o/--output``
(a folder or a file). Whether an output can be written is checked by the command itself
(:mod:`eomgen.common.output`: one error line, not click's usage text). ``--debug`` comes with the error
handling (:func:`eomgen.cli.handling.handle_errors`).
"""

from __future__ import annotations

from pathlib import Path

import click

from ..robots import EXAMPLES

#: ``--scene`` of most commands.
SCENE_HELP = ("Scene file (YAML, docs/scenes.md): reduce the robot to what the scene moves "
              "first (e.g. examples/scenes/panda_two_joints.yaml).")

#: ``--quiet`` of most commands.
QUIET_HELP = ("No progress on stderr (stage lines in a log, an updating line or bar on a "
              "terminal).")


#: Where ``--mimic`` leaves its value in the command's context (``ctx.meta``), for
#: :func:`eomgen.cli.loading.load`.
MIMIC_KEY = "eomgen.mimic"
MIMIC_CHOICES = ("honour", "independent")


def description_argument(required: bool = False):
    """DESCRIPTION: a URDF, DH-table YAML, eomgen YAML or MJCF file, or the name of a bundled
    example (:data:`eomgen.robots.EXAMPLES`, e.g. ``scara_rrp``; a file of that name wins);
    optional (the bundled planar 2-link arm, :func:`eomgen.cli.loading.default_description`)
    unless ``required``. With it comes ``--mimic`` (how the description's coupled joints are
    read), kept in the context, not passed to the command (:data:`MIMIC_KEY`)."""
    argument = click.argument("description", required=required, callback=_file_or_example,
                              type=click.Path(dir_okay=False, path_type=Path))
    mimic = click.option(
        "--mimic", type=click.Choice(MIMIC_CHOICES), default=None, expose_value=False,
        callback=_remember_mimic,
        help="Coupled joints of the description (URDF <mimic>, MJCF joint equalities): "
             "'honour' (the default) makes each follower move with its leader, "
             "'independent' reads each follower as an independent joint (one warning each).")
    return lambda command: argument(mimic(command))


def _remember_mimic(ctx, param, value: str | None) -> str | None:
    if value is not None:
        ctx.meta[MIMIC_KEY] = value
    return value


def _file_or_example(ctx, param, value: Path | None) -> Path | None:
    """``value`` itself when it exists (or is not an example's name), else the bundled
    example's file of that name, as :func:`eomgen.example_path` gives it in Python."""
    if value is None or value.exists():
        return value
    return EXAMPLES.get(str(value), value)


strict_option = click.option(
    "--strict", is_flag=True,
    help="Refuse inertias that break the triangle inequality and a URDF root that looks like a "
         "floating base, instead of warning (only about what a --scene keeps).")


def quiet_option(help: str = QUIET_HELP):
    """``--quiet``: no :class:`eomgen.common.progress.Progress` lines."""
    return click.option("--quiet", is_flag=True, help=help)


def scene_option(help: str = SCENE_HELP):
    """``--scene`` (parameter ``scene_path``): a scene file that reduces the model first."""
    return click.option("--scene", "scene_path", default=None,
                        type=click.Path(dir_okay=False, path_type=Path), help=help)


def output_folder_option(default: str):
    """``-o/--output`` (parameter ``outdir``) for a folder (see
    :func:`eomgen.common.output.check_output_folder`)."""
    return click.option("-o", "--output", "outdir", default=default, show_default=True,
                        type=click.Path(path_type=Path), help="Output folder.")


def output_file_option(help: str, default: str | None = None):
    """``-o/--output`` (parameter ``output``) for one file (see
    :func:`eomgen.common.output.check_output_file`); the default is shown when there is one."""
    return click.option("-o", "--output", "output", default=default,
                        show_default=default is not None, type=click.Path(path_type=Path),
                        help=help)
