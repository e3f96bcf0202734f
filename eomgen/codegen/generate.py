"""``eomgen generate``: description → derived dynamics → files of every chosen backend.

All files are computed in memory first; only then are they written, into a staging folder next
to the output folder, and moved into place with signals held back, so an error or an interrupt
leaves either the previous output or the complete new one, never a mixture.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Callable, Iterable, Sequence

from ..dynamics import derive
from ..cache import CacheRequest, cache_folder, render_cached
from ..errors import GenerationError
from ..model import RobotModel, snap_summary
from ..common.output import checked_stem, import_collisions, write_atomically  # noqa: F401
from ..common.progress import plural, reporting
from ..outputs import OUTPUTS
from ..common.output import GeneratedFile
from .job import make_job
from .registry import available_backends
from .functions import derived_outputs, select_functions

Progress = Callable[[str], None]


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


def render_files(model: RobotModel, backends: Sequence[str], progress: Progress = lambda _: None,
                 functions: Iterable[str] | None = None, notes: Sequence[str] = (),
                 build: bool = True, stem: str | None = None) -> list[GeneratedFile]:
    """Derive ``model`` once and run each backend; nothing is written.

    ``functions`` (default: all, see :func:`~eomgen.codegen.functions.select_functions`) are the
    functions the modules export; only the outputs they need are derived. ``notes`` are extra
    header lines of every file. ``build=False`` renders the text files only: nothing is
    compiled, so the C backend's ``.so`` and the fast backend's extension module are left out
    (the other files are the same, byte for byte). ``stem`` names the files and modules
    (default: the robot's name; see :func:`eomgen.codegen.make_job`).
    """
    start = time.perf_counter()
    outputs = derived_outputs(functions)
    snapped = dict(model.info).get("snapped")
    if snapped:
        progress(snap_summary(snapped))
    progress(f"deriving {', '.join(outputs)} of {model.name} ({plural(model.dof, 'joint')})")
    dynamics = derive(model, outputs=outputs, simplify=False)
    job = make_job(dynamics, functions, notes, stem=stem)
    progress(f"derived in {time.perf_counter() - start:.2f} s; "
             + ", ".join(f"{s.name} {s.operation_count} ops" for s in job.specs))
    return render_job(job, backends, progress, build)


def usable_backends(names: Sequence[str], functions: Iterable[str] | None = None
                    ) -> tuple[list[str], list[str]]:
    """Split backend ``names`` into those that can serve ``functions`` and those that cannot
    (a backend whose ``needs`` are not all derived for them, e.g. the LaTeX derivation, which
    documents M, C and g, when only g is asked)."""
    outputs = set(derived_outputs(functions))
    registry = available_backends()
    usable = [n for n in names if set(registry[n].needs) <= outputs]
    return usable, [n for n in names if n not in usable]


def render_job(job, backends: Sequence[str], progress: Progress = lambda _: None,
               build: bool = True) -> list[GeneratedFile]:
    """Run each backend on ``job`` (see :func:`eomgen.codegen.make_job`); nothing is written.
    ``build=False`` emits the text files without compiling (:meth:`eomgen.codegen.Backend.files`).

    Raises
    ------
    GenerationError
        When a backend needs outputs the job's dynamics lack (see :func:`usable_backends`).
    """
    files: list[GeneratedFile] = []
    registry = available_backends()
    for function in job.functions:  # a composed function some backends leave out
        composing = OUTPUTS[function].backends
        if composing is None:
            continue
        left = [name for name in backends if name not in composing]
        if left and len(left) == len(backends):
            raise GenerationError(
                f"{function} is composed by the {', '.join(composing)} backends only; "
                f"{', '.join(left)} cannot export it: choose one of those")
        if left:
            progress(f"{', '.join(left)}: {function} left out (composed by "
                     f"{', '.join(composing)} only)")
    for name in backends:
        missing = [o for o in registry[name].needs if o not in job.dynamics.outputs]
        if missing:
            raise GenerationError(
                f"the {name} backend needs {', '.join(registry[name].needs)} derived, but the "
                f"functions asked for ({', '.join(job.functions)}) do not need "
                f"{', '.join(missing)}; ask for more outputs or choose other backends")
    for name in backends:
        start = time.perf_counter()
        progress(f"{name}: generating")  # the C backend compiles: a stage of its own in a log
        with reporting(progress):  # a build step reports its compile (the fast backend's units)
            produced = registry[name].files(job, build)
        progress(f"{name}: {', '.join(f.name for f in produced)} "
                 f"({time.perf_counter() - start:.2f} s)")
        files.extend(produced)
    names = [f.name for f in files]
    duplicates = {n for n in names if names.count(n) > 1}
    if duplicates:  # pragma: no cover - backends use distinct suffixes
        raise GenerationError(f"backends produced the same file twice: {sorted(duplicates)}")
    collisions = import_collisions(names)
    if collisions:  # pragma: no cover - backends name their files apart (a test checks it)
        raise GenerationError("files Python would import under one name: "
                              + "; ".join(", ".join(group) for group in collisions))
    return files


def generate(model: RobotModel, outdir: Path, backends: str | Sequence[str] = "all",
             symbolic: Iterable[str] | None = None, progress: Progress = lambda _: None,
             functions: Iterable[str] | None = None, cache: bool | CacheRequest = True,
             cache_dir: Path | None = None, build: bool = True, stem: str | None = None
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
    functions:
        The functions to generate (default: all; names or short names ``M``, ``C``, ``g``,
        ``tau``, see :func:`~eomgen.codegen.functions.select_functions`). With ``"all"``
        backends, a backend that cannot serve them (the LaTeX derivation needs M, C and g) is
        left out, with a progress line; a backend named explicitly is an error.
    cache:
        Take the files of an identical earlier request from the derivation cache and store new
        ones there (:mod:`eomgen.cache`); ``False`` derives afresh and stores nothing.
    cache_dir:
        The cache folder (default: :func:`eomgen.cache.default_cache_dir`).
    build:
        Compile what the backends compile (the C backend's shared library, the fast
        backend's extension module); ``False`` writes their text files only.
    stem:
        The files' and modules' name (``<stem>_numpy.py``; a Python identifier); default: the
        robot's name (:func:`eomgen.common.output.module_name`).
    """
    stem = checked_stem(stem)
    chosen = select_backends(backends)
    if functions is not None:
        try:
            functions = select_functions(functions)
        except ValueError as exc:
            raise GenerationError(str(exc)) from None
        if backends == "all" or list(backends) == ["all"]:
            chosen, skipped = usable_backends(chosen, functions)
            for name in skipped:
                progress(f"{name}: skipped (needs {', '.join(available_backends()[name].needs)})")
    model = keep_symbolic(model, symbolic)
    # build=False is passed only when given, so that the cache keys of building calls (the
    # options are part of the key) are those of earlier versions
    options = {} if build else {"build": False}
    if stem is not None:  # likewise: part of the key only when given
        options["stem"] = stem
    with cache_folder(cache_dir):  # the fast module's compiled objects go there too
        files = render_cached(render_files, model, chosen, progress, cache=cache,
                              cache_dir=cache_dir, functions=functions, **options)
    return write_atomically(files, Path(outdir))
