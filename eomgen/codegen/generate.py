"""``eomgen generate``: description → derived dynamics → files of every chosen backend.

All files are computed in memory first; only then are they written, into a staging folder next
to the output folder, and moved into place with signals held back, so an error or an interrupt
leaves either the previous output or the complete new one, never a mixture.
"""

from __future__ import annotations

import os
import shutil
import signal
import tempfile
import time
from pathlib import Path
from typing import Callable, Iterable, Sequence

from ..dynamics import ALL_OUTPUTS, derive
from ..errors import EomgenError
from ..model import RobotModel
from . import GeneratedFile, available_backends, make_job

Progress = Callable[[str], None]


class GenerationError(EomgenError):
    """A generation request that cannot be carried out (unknown backend, unknown parameter)."""


def select_backends(names: str | Sequence[str]) -> list[str]:
    """Backend names from ``"numpy,casadi"`` or ``"all"``, in the registry's order."""
    known = available_backends()
    if isinstance(names, str):
        names = [n.strip() for n in names.split(",") if n.strip()]
    if list(names) == ["all"]:
        return list(known)
    unknown = [n for n in names if n not in known]
    if unknown or not names:
        raise GenerationError(f"unknown backend {', '.join(unknown) or '(none given)'}; "
                              f"choose from {', '.join(known)} or all")
    return [n for n in known if n in names]


def keep_symbolic(model: RobotModel, names: Iterable[str] | None) -> RobotModel:
    """The model with every parameter not in ``names`` replaced by its value.

    ``None`` keeps all of the description's parameters symbolic.
    """
    if names is None:
        return model
    names = list(names)
    declared = {p.name: p for p in model.parameters}
    unknown = [n for n in names if n not in declared]
    if unknown:
        raise GenerationError(
            f"{model.source}: --symbolic: unknown parameter {', '.join(unknown)}"
            + (f" (the description declares {', '.join(sorted(declared))})" if declared
               else " (the description declares no parameters)"))
    fixed = {p.symbol: p.value for p in model.parameters if p.name not in names}
    missing = [p.name for p in model.parameters if p.name not in names and p.value is None]
    if missing:
        raise GenerationError(f"{model.source}: parameter {', '.join(missing)} has no value; "
                              "keep it symbolic (--symbolic) or give it a value")
    return model.substitute(fixed)


def render_files(model: RobotModel, backends: Sequence[str], progress: Progress = lambda _: None
                 ) -> list[GeneratedFile]:
    """Derive ``model`` once and run each backend; nothing is written."""
    start = time.perf_counter()
    progress(f"deriving M, C, g and tau of {model.name} ({model.dof} joints)")
    dynamics = derive(model, outputs=ALL_OUTPUTS, simplify=False)
    job = make_job(dynamics)
    progress(f"derived in {time.perf_counter() - start:.2f} s; "
             + ", ".join(f"{s.name} {s.operation_count} ops" for s in job.specs))
    files: list[GeneratedFile] = []
    registry = available_backends()
    for name in backends:
        start = time.perf_counter()
        produced = registry[name].generate(job)
        progress(f"{name}: {', '.join(f.name for f in produced)} "
                 f"({time.perf_counter() - start:.2f} s)")
        files.extend(produced)
    names = [f.name for f in files]
    duplicates = {n for n in names if names.count(n) > 1}
    if duplicates:  # pragma: no cover - backends use distinct suffixes
        raise GenerationError(f"backends produced the same file twice: {sorted(duplicates)}")
    return files


def write_atomically(files: Sequence[GeneratedFile], outdir: Path) -> list[Path]:
    """Write ``files`` into ``outdir``: all of them or, on any failure, none.

    Files are first written into a staging folder beside ``outdir``; then they are moved in with
    ``os.replace`` while SIGINT and SIGTERM are held back, and the staging folder is removed.
    """
    outdir = Path(outdir)
    outdir.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{outdir.name}.staging-", dir=outdir.parent))
    try:
        for f in files:
            target = staging / f.name
            if isinstance(f.content, bytes):
                target.write_bytes(f.content)
            else:
                target.write_text(f.content, encoding="utf-8", newline="\n")
        blocked = {signal.SIGINT, signal.SIGTERM}
        previous = signal.pthread_sigmask(signal.SIG_BLOCK, blocked)
        try:
            outdir.mkdir(exist_ok=True)
            for f in files:
                os.replace(staging / f.name, outdir / f.name)
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, previous)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return [outdir / f.name for f in files]


def generate(model: RobotModel, outdir: Path, backends: str | Sequence[str] = "all",
             symbolic: Iterable[str] | None = None, progress: Progress = lambda _: None
             ) -> list[Path]:
    """Generate the chosen backends' files for ``model`` into ``outdir``; returns their paths.

    Parameters
    ----------
    model:
        The robot (see :func:`eomgen.load`).
    outdir:
        Output folder, created when missing; existing files of the same names are replaced.
    backends:
        ``"all"`` or names among ``numpy``, ``casadi``, ``c``, ``latex``.
    symbolic:
        Parameters to keep symbolic (keyword arguments of the generated functions); the others
        are replaced by their values. ``None`` keeps all of the description's parameters.
    progress:
        Called with a line of text at each stage.
    """
    chosen = select_backends(backends)
    model = keep_symbolic(model, symbolic)
    files = render_files(model, chosen, progress)
    return write_atomically(files, Path(outdir))
