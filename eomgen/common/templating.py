"""The one Jinja environment of eomgen, and where the templates live (code generation, the
teaching handouts and the notebook's cells all render through it).

Templates only loop over printed strings: every decision is made in Python before rendering.
The templates sit in the top-level ``templates/`` folder of a source checkout and are shipped
inside the wheel as ``eomgen/templates`` (see ``pyproject.toml``); :data:`TEMPLATES_DIR` finds
whichever is present.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import jinja2

_PACKAGE = Path(__file__).resolve().parents[1]  # eomgen/ (this module is eomgen/common/)


def _templates_dir() -> Path:
    for candidate in (_PACKAGE / "templates", _PACKAGE.parent / "templates"):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError("eomgen templates not found (broken installation)")


#: Folder holding one sub-folder of templates per backend.
TEMPLATES_DIR: Path = _templates_dir()


@lru_cache(maxsize=1)
def environment() -> jinja2.Environment:
    """The shared Jinja environment: strict about undefined names, no autoescaping (backends
    escape what they print for their own language), whitespace control on."""
    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(TEMPLATES_DIR)),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
        autoescape=False,
    )


def render(template: str, **context) -> str:
    """Render ``template`` (a path below :data:`TEMPLATES_DIR`, e.g. ``numpy/module.py.jinja``)."""
    return environment().get_template(template).render(**context)


def render_block(template: str, block: str, **context) -> str:
    """Render one ``{% block %}`` of ``template`` on its own, with ``context`` (the notebook
    renders each of its cells so: one block per cell, the order chosen in Python)."""
    compiled = environment().get_template(template)
    return "".join(compiled.blocks[block](compiled.new_context(context)))
