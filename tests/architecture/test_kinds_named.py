"""No algorithm names a special joint kind (issue 39): the modules outside the joint kinds
(``eomgen/model/joints/``) and the parsers that name the free flyer (``free_flyer``,
``FREE_FLYER``) or the list of joints with a chart (``quaternion_joints``) are the homes that
hold those names on purpose, listed in :data:`NAMING_TODAY` with why. A module that starts
naming them fails, and so does an entry that no longer does (the list only shrinks).

The algorithms ask the kinds instead: ``model.nq`` against ``model.dof``,
``model.joint_places`` (each joint with its kind), the chart homes of their layer, a kind's
``base``.
"""

from __future__ import annotations

import re

from support import ROOT

PACKAGE = ROOT / "eomgen"
NAMES = re.compile(r"free_flyer|FREE_FLYER|quaternion_joints")

#: The modules that name them today, and why.
NAMING_TODAY: dict[str, str] = {
    # public names kept for users (API and old paths)
    "eomgen/moved.py": "the old module paths and names, kept one more release",
    "eomgen/model/robot.py": "RobotModel.free_flyer and .quaternion_joints, public properties",
    "eomgen/model/floating.py": "add_free_flyer: the free flyer put under a robot",
    "eomgen/numeric/floating_base.py": "to_free_flyer, from_free_flyer: the Euler chart's maps",
}


def naming() -> set[str]:
    found = set()
    for path in PACKAGE.rglob("*.py"):
        relative = path.relative_to(ROOT).as_posix()
        if relative.startswith(("eomgen/model/joints/", "eomgen/parsers/")):
            continue
        if NAMES.search(path.read_text(encoding="utf-8")):
            found.add(relative)
    return found


def test_only_the_listed_homes_name_a_special_kind():
    found = naming()
    assert sorted(found - set(NAMING_TODAY)) == [], "name no kind: ask the kinds (module docstring)"
    assert sorted(set(NAMING_TODAY) - found) == [], "no longer naming: drop it from NAMING_TODAY"
