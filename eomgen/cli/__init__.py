"""Command line interface: the ``eomgen`` group and its commands, a module per group.

=====================  =====================================================================
module                 what
=====================  =====================================================================
``options``            the arguments and options several commands share (DESCRIPTION,
                       ``--scene``, ``--quiet``, ``--strict``, ``-o/--output``), declared once
``handling``           how a command ends: errors, interrupts and warnings on stderr
``loading``            DESCRIPTION and ``--scene`` to a model; the outputs' file-name stem
``generate_verify``    ``eomgen generate``, ``eomgen verify``
``notebook_teach``     ``eomgen notebook``, ``eomgen teach``
``bench_simulate``     ``eomgen bench``, ``eomgen simulate`` (:mod:`eomgen.analysis`)
``excite_identify``    ``eomgen excite``, ``eomgen identify`` (:mod:`eomgen.identification`)
=====================  =====================================================================

Exit codes: 0 success, 1 a verification check failed, 2 bad input (one line on stderr naming the
file, the element and the problem; a traceback only with ``--debug``), 130 interrupted (SIGINT,
Ctrl-C) and 143 terminated (SIGTERM), each with the one line ``eomgen: interrupted``.

Every command that writes checks first that its output can be written (:mod:`eomgen.common.output`),
so that a bad ``-o`` is one error line before minutes of work. Progress goes to stderr through
one :class:`eomgen.common.progress.Progress` (``--quiet`` on every command silences it).

The command modules import SymPy, NumPy and the rest only when a command runs: ``eomgen
--help`` and a cached ``eomgen generate`` stay light.
"""

from __future__ import annotations

import click

from ..common.version import __version__
from .bench_simulate import bench, simulate
from .excite_identify import excite, identify
from .generate_verify import generate, verify
from .loading import load_reduced
from .notebook_teach import notebook, teach

__all__ = ["main", "load_reduced"]

#: The name tests imported from the single-module CLI (deprecated: use :func:`load_reduced`,
#: from :mod:`eomgen.cli.loading`).
_load_reduced = load_reduced


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
      eomgen teach scara_rrp                 # a bundled example by name

    DESCRIPTION, in every command, is a URDF, DH-table YAML or eomgen YAML file, or the name of
    a bundled example (cylindrical_rpp, elbow_rrr, planar_2link, puma560_arm3, puma560_dh,
    scara_rrp, stanford_rrp); a file of that name wins.
    """
    if ctx.invoked_subcommand is None:  # plain ``eomgen``: the help, and success
        click.echo(ctx.get_help())
        ctx.exit(0)


for _command in (verify, generate, notebook, teach, bench, simulate, excite, identify):
    main.add_command(_command)
del _command
