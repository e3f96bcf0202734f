"""``eomgen generate --scene``: a robot and a scene → the reduced model → files and a report.

The scene (:mod:`eomgen.scene`) is applied first (:func:`eomgen.reduction.apply_scene`); the
reduced model is derived for the scene's outputs only, every chosen backend runs on it, and a
report ``<robot>_scene_report.md`` of what was merged, locked and dropped and what that saved is
written beside the generated files, all of them or none (as :func:`~.generate.generate` does).
"""

from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Sequence

from ..cache import Cache, CacheRequest, cache_folder
from ..dynamics import derive
from ..model import RobotModel
from ..common.output import checked_stem
from ..common.progress import plural
from ..reduction import DerivationCost, ReductionReport, apply_scene
from ..scene import Scene
from ..common.output import GeneratedFile
from .derivation_cost import MEASURE_TIMEOUT, derivation_cost, measure_derivation
from .job import make_job
from .functions import derived_outputs
from .generate import (
    Progress,
    keep_symbolic,
    render_job,
    select_backends,
    usable_backends,
    write_atomically,
)

REPORT_SUFFIX = "_scene_report.md"


@dataclass(frozen=True)
class SceneGeneration:
    """What :func:`render_scene_files` produced: the files (report included), the report and
    the derivation costs (``before`` only when the whole description was measured)."""

    files: tuple[GeneratedFile, ...]
    report: ReductionReport
    markdown: str
    before: DerivationCost | None
    after: DerivationCost


def render_scene_files(model: RobotModel, scene: Scene | None, backends: Sequence[str],
                       symbolic: Iterable[str] | None = None,
                       progress: Progress = lambda _: None, explain: bool = False,
                       timeout: float = MEASURE_TIMEOUT, build: bool = True,
                       stem: str | None = None) -> SceneGeneration:
    """Apply ``scene`` to ``model``, derive and render; nothing is written. The files include
    the report when ``scene`` is given (None applies the empty scene: merging only);
    ``build=False`` compiles nothing (see :func:`~.generate.render_files`); ``stem`` names the
    files (default: the robot's name).

    With ``explain``, the whole description and the reduced model are both derived again, each
    in a fresh process (:func:`~.derivation_cost.measure_derivation`, at most ``timeout``
    seconds), so that the report compares like with like; otherwise the report gives the cost
    of the derivation made for the files.
    """
    start = time.perf_counter()
    reduced, report = apply_scene(model, scene)
    progress(f"scene {Path(report.scene).name}: {report.moving_summary()}, "
             f"{report.before.links} links in the description, {report.after.links} in the "
             f"model ({time.perf_counter() - start:.2f} s)"
             + (f"; {report.mobility.describe()}" if report.mobility is not None else ""))
    reduced = keep_symbolic(reduced, symbolic)
    functions = report.outputs
    outputs = derived_outputs(functions)
    progress(f"deriving {', '.join(outputs)} of {reduced.name} "
             f"({plural(reduced.dof, 'joint')})")
    dynamics = derive(reduced, outputs=outputs, simplify=False)
    after = derivation_cost(dynamics)
    notes = _header_notes(report, scene)
    job = make_job(dynamics, functions, notes, stem=stem)
    progress(f"derived in {after.seconds:.2f} s; "
             + ", ".join(f"{s.name} {s.operation_count} ops" for s in job.specs))
    files = render_job(job, backends, progress, build)
    before = None
    if explain:
        whole = _with_scene_parameters(model, reduced)
        progress(f"measuring the whole description ({plural(whole.dof, 'joint')}) for comparison, "
                 "at most "
                 f"{timeout:g} s")
        before = measure_derivation(whole, outputs, timeout)
        progress("measuring the reduced model the same way")
        after = measure_derivation(reduced, outputs, timeout)
    markdown = report.markdown(before, after)
    if scene is not None:
        files = files + [GeneratedFile(job.stem + REPORT_SUFFIX, markdown, golden=False)]
    return SceneGeneration(tuple(files), report, markdown, before, after)


def _with_scene_parameters(model: RobotModel, reduced: RobotModel) -> RobotModel:
    """``model`` with the parameters fixed that the reduced model fixed (a fair comparison)."""
    kept = {p.name for p in reduced.parameters}
    fixed = {p.symbol: p.value for p in model.parameters
             if p.name not in kept and p.value is not None}
    return model.substitute(fixed) if fixed else model


def _header_notes(report: ReductionReport, scene: Scene | None) -> tuple[str, ...]:
    if scene is None:
        return ()
    path = Path(scene.source)
    digest = hashlib.sha256(path.read_bytes()).hexdigest() if path.is_file() else "0" * 64
    return (f"Reduced by scene {path.name!r} (sha256 {digest[:16]}): "
            f"{report.moving_summary()}; see the scene report.",)


def generate_scene(model: RobotModel, scene: Scene | None, outdir: Path,
                   backends: str | Sequence[str] = "all", symbolic: Iterable[str] | None = None,
                   progress: Progress = lambda _: None, explain: bool = False,
                   timeout: float = MEASURE_TIMEOUT, cache: bool | CacheRequest = False,
                   cache_dir: Path | None = None, build: bool = True, stem: str | None = None
                   ) -> tuple[list[Path], SceneGeneration]:
    """Generate the chosen backends' files for ``model`` reduced by ``scene``, and the scene
    report, into ``outdir`` (all files or none); returns their paths and what was produced.

    Backends as for :func:`~.generate.generate`: with ``"all"``, a backend that cannot serve the
    scene's outputs (the LaTeX derivation needs M, C and g) is left out with a progress line.
    ``symbolic`` narrows further the parameters the scene keeps symbolic. ``cache``: a
    :class:`~eomgen.cache.CacheRequest` (``eomgen generate --scene`` keys the description and
    scene files before reading them, :func:`eomgen.cache.command_request`) stores the files
    under its key in the derivation cache (folder ``cache_dir``); anything else stores nothing.
    ``build=False`` writes the text files only (nothing compiled). ``stem`` names the files
    (default: the robot's name), as in :func:`~.generate.generate`.
    """
    stem = checked_stem(stem)
    chosen = select_backends(backends)
    outputs = scene.outputs if scene is not None else None
    if backends == "all" or list(backends) == ["all"]:
        # The package's registry, complete once eomgen.codegen has imported every backend.
        from .registry import available_backends

        chosen, skipped = usable_backends(chosen, outputs)
        for name in skipped:
            progress(f"{name}: skipped (needs {', '.join(available_backends()[name].needs)})")
    with cache_folder(cache_dir):  # the fast module's compiled objects go there
        produced = render_scene_files(model, scene, chosen, symbolic, progress, explain,
                                      timeout, build, stem)
    if isinstance(cache, CacheRequest) and build:  # the key says nothing of build=False
        Cache(cache_dir).put(cache.key, produced.files, tuple(cache.notices))
    return write_atomically(produced.files, Path(outdir)), produced
