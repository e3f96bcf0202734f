"""Example robots bundled with eomgen (plain YAML files shipped as package data).

>>> from eomgen.robots import EXAMPLES, example_path
>>> sorted(EXAMPLES)  # doctest: +NORMALIZE_WHITESPACE
['cylindrical_rpp', 'elbow_rrr', 'planar_2link', 'puma560_arm3', 'puma560_dh', 'scara_rrp',
 'stanford_rrp']
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
    # The teaching set: standard DH, symbolic parameters, closed forms in each file's header.
    "elbow_rrr": _HERE / "elbow_rrr.yaml",  # elbow (articulated) arm
    "scara_rrp": _HERE / "scara_rrp.yaml",  # SCARA
    "stanford_rrp": _HERE / "stanford_rrp.yaml",  # Stanford-type spherical arm
    "cylindrical_rpp": _HERE / "cylindrical_rpp.yaml",  # cylindrical arm
    "puma560_arm3": _HERE / "puma560_arm3.yaml",  # PUMA 560 waist, shoulder, elbow
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
