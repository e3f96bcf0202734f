"""A description's text written into a teaching document: the notebook holds the description
(and the scene) it was made from, so that it runs wherever it is copied; a description that
names files of its own (an MJCF's includes or meshes) is loaded by its path relative to the
notebook instead. This module says which, as data; the notebook's template prints the cells."""

from __future__ import annotations

import ast
import os
from dataclasses import dataclass, replace
from pathlib import Path


def text_literal(text: str) -> str:
    r'''A Python literal of ``text`` to read in a cell: a triple-quoted string, one line of the
    cell per line of ``text``, when that reads back as ``text`` (a description's usual case);
    else :func:`repr` (one long line, but exact).

    >>> print(text_literal('robot: "arm"\nlinks: []\n'))
    """\
    robot: "arm"
    links: []
    """
    '''
    body = text.replace("\\", "\\\\").replace('"""', '\\"""')
    if body.endswith('"'):
        body = body[:-1] + '\\"'
    literal = '"""\\\n' + body + '"""'
    try:
        if ast.literal_eval(literal) == text:
            return literal
    except (SyntaxError, ValueError):  # a character a string literal cannot hold as it is
        pass
    return repr(text)


def _external_files(path: Path, text: str) -> bool:
    """Whether the description names other files that its parser reads (an MJCF ``<include>``,
    mesh or height field: MuJoCo's compiler opens them). A URDF's meshes are not read (the
    dynamics need none), and eomgen's YAML and DH files name no files."""
    from ..parsers.mjcf import is_mjcf  # the MJCF sniffer: no MuJoCo import

    if path.suffix.lower() != ".xml" or not is_mjcf(text):
        return False
    from defusedxml import ElementTree  # the parsers' XML reader, as for a URDF

    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError:
        return True  # let the compiler read it from its folder, where it compiled
    return any(element.get("file") for element in root.iter())


def _read_text(path: Path) -> str | None:
    try:
        return path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        return None


@dataclass(frozen=True)
class EmbeddedSource:
    """Where the notebook's model comes from, as the cells that make it print it
    (templates/notebook/cells.jinja, blocks ``robot_text``, ``description_code``,
    ``scene_code`` and ``setup_code``).

    ``name``: the description's file name; ``description``: its text as a Python literal
    (:func:`text_literal`) when it is written in, else None and ``relative``: its path
    relative to the notebook; ``scene``, ``scene_text``: the scene's file name and its text as
    a literal, or None."""

    name: str
    description: str | None = None
    relative: str | None = None
    scene: str | None = None
    scene_text: str | None = None

    @property
    def name_literal(self) -> str:
        return repr(self.name)

    @property
    def relative_literal(self) -> str:
        return repr(self.relative)

    @property
    def scene_literal(self) -> str:
        return repr(self.scene)


def embedded_source(description: Path | None, scene: Path | None,
                    notebook: Path | None) -> EmbeddedSource:
    """How the notebook makes ``model``: the description's text (and the scene's) written into
    the notebook, so that it runs wherever it is copied; or, for a description that names
    files of its own (MJCF meshes, includes) or is not UTF-8 text, its path relative to the
    notebook (``notebook``: where it will be written; None: the current folder).

    >>> from eomgen.robots import example_path
    >>> source = embedded_source(example_path("planar_2link"), None, None)
    >>> source.name, source.relative, source.description.splitlines()[1][:14]
    ('planar_2link.yaml', None, '# The textbook')
    """
    path = Path(description) if description is not None else None
    if path is None:  # the bundled planar arm
        from ..robots import example_path

        path = example_path("planar_2link")
    text = _read_text(path)
    if text is not None and not _external_files(path, text):
        source = EmbeddedSource(path.name, description=text_literal(text))
    else:
        where = Path(notebook).resolve().parent if notebook is not None else Path.cwd()
        relative = Path(os.path.relpath(path.resolve(), where)).as_posix()
        source = EmbeddedSource(path.name, relative=relative)
    if scene is None:
        return source
    scene = Path(scene)
    return replace(source, scene=scene.name,
                   scene_text=text_literal(scene.read_text(encoding="utf-8")))


__all__ = ["EmbeddedSource", "embedded_source", "text_literal"]
