"""Example robots bundled with eomgen (plain YAML files shipped as package data).

>>> from eomgen.robots import EXAMPLES, example_path
>>> sorted(EXAMPLES)
['planar_2link', 'puma560_dh']
>>> example_path("planar_2link").name
'planar_2link.yaml'
"""

from __future__ import annotations

from pathlib import Path

from ..errors import EomgenError

_HERE = Path(__file__).resolve().parent

#: Name of the example the CLI uses when no description file is given.
DEFAULT = "planar_2link"

#: Example name → path of its description file.
EXAMPLES: dict[str, Path] = {
    "planar_2link": _HERE / "planar_2link.yaml",  # eomgen YAML: the textbook planar 2R arm
    "puma560_dh": _HERE / "puma560_dh.yaml",  # standard DH table with published dynamics
}


def example_path(name: str = DEFAULT) -> Path:
    """Path of the bundled example robot ``name`` (a key of :data:`EXAMPLES`).

    Raises
    ------
    EomgenError
        For an unknown name; the message lists the known ones.
    """
    try:
        return EXAMPLES[name]
    except (KeyError, TypeError):
        raise EomgenError(
            f"unknown example robot {name!r} (known: {', '.join(sorted(EXAMPLES))})") from None
