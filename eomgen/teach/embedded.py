"""A description's text written into a teaching document: the notebook holds the description
(and the scene) it was made from, so that it runs wherever it is copied; a description that
names files of its own (an MJCF's includes or meshes) is loaded by its path relative to the
notebook instead."""

from __future__ import annotations

import ast
import os
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


def load_cells(description: Path | None, scene: Path | None, notebook: Path | None):
    """The cells that make ``model``: the description's text (and the scene's) written into
    the notebook, so that it runs wherever it is copied; or, for a description that names
    files of its own (MJCF meshes, includes) or is not UTF-8 text, its path relative to the
    notebook (``notebook``: where it will be written; None: the current folder).

    Returns ``(markdown, [code cells])``."""
    path = Path(description) if description is not None else None
    if path is None:  # the bundled planar arm
        from ..robots import example_path

        path = example_path("planar_2link")
    text = _read_text(path)
    embed = text is not None and not _external_files(path, text)
    cells = []
    if embed:
        markdown = (f"The description `{path.name}` is written into this notebook, so that the "
                    "notebook runs wherever it is copied: edit it and run the notebook again "
                    "to change the robot. It is written to a temporary folder under its own name "
                    "(the suffix tells the format) and loaded from there.")
        cells.append(f"DESCRIPTION = {text_literal(text)}")
        load = ("with tempfile.TemporaryDirectory() as folder:\n"
                f"    path = Path(folder) / {path.name!r}\n"
                "    path.write_text(DESCRIPTION, encoding=\"utf-8\")\n"
                "    model = eomgen.load(path)")
    else:
        where = Path(notebook).resolve().parent if notebook is not None else Path.cwd()
        relative = Path(os.path.relpath(path.resolve(), where)).as_posix()
        markdown = (f"The description `{path.name}` names files of its own (meshes, "
                    "includes), so it is loaded from its folder: keep it at "
                    f"`{relative}`, relative to this notebook (Jupyter runs a notebook in "
                    "its own folder).")
        load = f"model = eomgen.load({relative!r})"
    if scene is not None:
        scene = Path(scene)
        markdown += (f" The scene `{scene.name}` (which joints move, what is locked) is "
                     "written in as well, and applied to the model.")
        cells.append(f"SCENE = {text_literal(scene.read_text(encoding='utf-8'))}")
        load += ("\nmodel = eomgen.apply_scene(model, eomgen.load_scene("
                 f"{scene.name!r}, text=SCENE)).model")
    return markdown, cells, load


__all__ = ["load_cells", "text_literal"]
