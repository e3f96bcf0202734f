"""C kernels backend (``kernels``): ``<robot>_kernels.c`` and ``<robot>_kernels.h``, the fast module's
arithmetic as plain C99 functions for C and C++ callers without Python (issue 25).

One function per printed output, named ``<robot>_<function>`` (e.g.
``panda_inverse_dynamics_derivatives(q, qd, qdd, p, out)``): the vector inputs, the parameters
kept symbolic ``p`` and a row-major ``out``. The bodies are the fast module's (same printer, same
program, same context: :func:`eomgen.codegen.backends.fast_backend.render_source`); composed
functions (``forward_dynamics``, which the fast module solves by Cholesky) are not kernels, use
``forward_dynamics_aba``. Templates: ``templates/kernels/kernels.{c,h}.jinja``. Nothing is compiled.
"""

from __future__ import annotations

from dataclasses import dataclass

from ...common.output import GeneratedFile
from ..job import Job
from ..registry import register
from .fast_backend import FastCPrinter, render_source


@dataclass(frozen=True)
class CKernelsConfig:
    """Options of the C kernels backend."""

    template: str = "kernels/kernels.c.jinja"
    header_template: str = "kernels/kernels.h.jinja"
    suffix: str = "_kernels"


@dataclass(frozen=True)
class _Rendering:
    template: str
    suffix: str


@register("kernels", "C kernels and header for C/C++ callers without Python (the fast module's "
          "arithmetic; nothing compiled)", config=CKernelsConfig, order=45,
          printer=FastCPrinter)
def generate_c(job: Job, config: CKernelsConfig = CKernelsConfig()) -> list[GeneratedFile]:
    stem = job.stem + config.suffix
    extra = dict(stem=stem, prefix=job.stem + "_", guard=(stem + "_H").upper())
    return [GeneratedFile(stem + ".h", render_source(job, _Rendering(config.header_template,
                                                                      config.suffix), **extra)),
            GeneratedFile(stem + ".c", render_source(job, _Rendering(config.template,
                                                                      config.suffix), **extra))]


__all__ = ["CKernelsConfig", "generate_c"]
