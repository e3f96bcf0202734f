"""Model reduction: the smallest :class:`~eomgen.model.RobotModel` a scene needs, and a report.

:func:`apply_scene` takes a robot and a :class:`~eomgen.scene.Scene` and returns a reduced
model whose M, C, g and τ equal those of the robot with the scene's joints locked, together
with a :class:`ReductionReport` of every step:

1. **Parameters**: those the scene does not keep symbolic take their values.
2. **Moving part**: the movable joints on the paths from ``base`` to each tip (every joint below
   ``base`` when no tips are given), less those the scene locks. Every *other* movable joint is
   locked too: at the scene's ``locked`` position or, when the scene does not list it, at 0
   (the report lists which).
3. **Locking**: a locked joint becomes a fixed joint at its position.
4. **Merging**: every link rigidly attached to a moving body (through fixed and locked joints,
   including whole subtrees outside the scene that hang from it, and the scene's payloads) is
   merged into it: the inertial parameters about the body origin (m, h = m c, I_O) are summed
   after moving each part into the body frame (parallel-axis theorem), then turned back into
   mass, centre of mass and inertia about it. A body with a single link keeps that link's data
   exactly.
5. **Dropping**: links rigidly attached to the world (the root and everything fixed to it,
   including the part above ``base`` once it is locked) cannot influence the moving joints and
   are dropped. The reduced model has one massless link for the world and one link per
   moving joint, whose joint is placed by the composed fixed transforms.
6. **Fixed frame**: when a single moving body hangs from the world, the fixed frame is moved to
   its joint frame at q = 0 (in :mod:`eomgen.reduction.apply`): no constant rotation or offset
   multiplies every later quantity; gravity is re-expressed in that frame. Joint-space M, C, g and τ are the same
   in any fixed frame.
7. **Notices**: of the description's findings that warn (or refuse under ``--strict``,
   :class:`~eomgen.model.Notice`), the reduced model keeps those that still matter: not those
   about joints none of which moves (a ``<mimic>`` finger the scene locks) nor those about links
   the scene drops; the floating-base notice only when the scene does not say
   ``fixed_base: true``. The report's notes list the others. :func:`load_for_scene` loads a
   description and warns only about what a scene keeps.
8. **Planar motion** is recognised (every moving revolute axis parallel to one normal n,
   prismatic axes perpendicular to it, in the root frame at q = 0): the report says so, and
   the component of gravity along n, which does no work in such motion, is dropped, so gravity
   along n gives g ≡ 0 exactly. Out-of-plane inertia terms are not removed from the model
   (the model stores inertia about the centre of mass, where they cannot be zeroed exactly);
   the derivation prunes what no output uses.

Structural zeros stay exact: locks at 0 give exact identity rotations, entries that come out of
composing exact numbers stay exact, and roundoff below :data:`ROUNDOFF` of a value's inputs is
snapped to an exact zero (as :data:`eomgen.model.SNAP_TOLERANCE` does for parsed rotations).

One module a concept, all importable from here: :mod:`~eomgen.reduction.apply` (the steps above),
:mod:`~eomgen.reduction.report` (the report), :mod:`~eomgen.reduction.inertia` (exact merged
inertial data) and :mod:`~eomgen.reduction.planar` (planar motion). What a derivation costs
is measured above the derivation, in :mod:`eomgen.codegen.derivation_cost`.

Examples
--------
>>> import eomgen
>>> from eomgen.scene import load_scene
>>> arm = eomgen.load(eomgen.example_path("planar_2link"))
>>> scene = load_scene("s.yaml", text="version: 1\\nlocked: {joint2: 0}\\nsymbolic: none")
>>> reduced, report = apply_scene(arm, scene)
>>> reduced.joint_names, report.locked[0].name
(('joint1',), 'joint2')
"""

from __future__ import annotations

from ..moved import moved_name
from .apply import SCENE_WORLD, apply_scene, load_for_scene
from .inertia import ROUNDOFF
from .planar import PlanarMotion, planar_motion
from .report import (DerivationCost, LockedJoint, MergedBody, ModelSize, Reduction,
                     ReductionReport)

__all__ = [
    "apply_scene", "load_for_scene", "SCENE_WORLD", "Reduction", "ReductionReport", "ModelSize",
    "LockedJoint", "MergedBody", "PlanarMotion", "planar_motion", "DerivationCost", "ROUNDOFF",
]


def __getattr__(name: str):
    """The names that moved from here (derivation_cost, ...): a warning, then the object at its
    new place (:data:`eomgen.moved.MOVED_NAMES`)."""
    return moved_name(__name__, name)
