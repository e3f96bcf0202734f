"""Teaching handouts: ``eomgen teach``.

The pipeline is the code generator's, for documents: a robot model →
:func:`~eomgen.teach.content.build_handout` (what the handout says, as plain data:
:mod:`eomgen.teach.document`) → a format of :mod:`eomgen.teach.formats` (LaTeX, PDF, Markdown,
HTML, each a template under ``templates/teach/``) → files written all at once
(:func:`eomgen.common.output.write_atomically`). The kinematic sketch is :mod:`eomgen.teach.sketch`.

>>> import eomgen
>>> from eomgen.teach import handout_files
>>> files = handout_files(eomgen.load(eomgen.example_path("planar_2link")), ["md"], check=False)
>>> [f.name for f in files]
['planar_2link_handout.md', 'planar_2link_sketch.svg']
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable, Sequence

from ..errors import GenerationError
from ..model import RobotModel
from ..common.output import GeneratedFile, write_atomically
from .content import build_handout
from .formats import FORMATS

__all__ = ["FORMATS", "build_handout", "handout_files", "parse_formats", "write_handout"]


def parse_formats(text: str) -> list[str]:
    """``"pdf,html"`` → ``["pdf", "html"]``; ``"all"`` → every format; unknown names raise
    :class:`GenerationError` listing the known ones."""
    names = [n.strip().lower() for n in text.split(",") if n.strip()]
    if names == ["all"]:
        return list(FORMATS)
    unknown = [n for n in names if n not in FORMATS]
    if unknown or not names:
        raise GenerationError(f"unknown handout format {', '.join(unknown) or repr(text)}; "
                              f"choose among {', '.join(FORMATS)} or all")
    return list(dict.fromkeys(names))


def handout_files(model: RobotModel, formats: Sequence[str],
                  progress: Callable[[str], None] = lambda message: None,
                  check: bool = True, scene=None) -> list[GeneratedFile]:
    """The files of ``model``'s handout in ``formats`` (names of :data:`FORMATS`), in memory;
    ``scene``: the reduction report when ``model`` comes from a scene."""
    handout = build_handout(model, progress, check=check, scene=scene)
    files: dict[str, GeneratedFile] = {}
    for name in formats:
        progress(f"writing the {name} handout" + (" (pdflatex)" if name == "pdf" else ""))
        for f in FORMATS[name](handout):
            files[f.name] = f
    return list(files.values())


def write_handout(model: RobotModel, outdir: Path, formats: Sequence[str] = ("pdf",),
                  progress: Callable[[str], None] = lambda message: None,
                  check: bool = True, scene=None) -> list[Path]:
    """Write ``model``'s handout into ``outdir``: every file of every format, or none."""
    return write_atomically(handout_files(model, formats, progress, check, scene), Path(outdir))
