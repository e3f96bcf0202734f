"""Code generation: derived dynamics → printed functions → files, one backend per target.

A backend is three small things (a printer, a config, a template folder under ``templates/``)
registered with :func:`register` in its own module under ``backends/`` (found by name, see
:mod:`.backends`); :func:`eomgen.codegen.generate.generate` runs the chosen backends on one
:class:`Job` and writes their files atomically. Adding a backend touches no other module.

Two stages per backend: *emit* renders text files (pure: templates and printers, no compiler)
and *build* turns emitted sources into binaries (the C backend's shared library, the fast
backend's extension module); only backends with something to compile register a build step.
``render_files(..., build=False)`` (and ``render_job``, ``generate``) emits without building,
for callers that read the text and throw binaries away.
"""

from __future__ import annotations

from ..common.output import GeneratedFile
from .job import Job, make_job
from .registry import BACKENDS, Backend, Loaded, available_backends, loadable_backends, register

__all__ = ["BACKENDS", "Backend", "GeneratedFile", "Job", "Loaded", "available_backends",
           "loadable_backends", "make_job", "register"]
