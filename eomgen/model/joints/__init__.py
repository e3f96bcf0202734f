"""Joint kinds as types: one module per kind, one instance of each in :data:`KINDS`.

===============  ====  ====  =====================================================
 kind             nq    nv    module
===============  ====  ====  =====================================================
 revolute          1     1    :mod:`~eomgen.model.joints.revolute` (and continuous)
 prismatic         1     1    :mod:`~eomgen.model.joints.prismatic`
 helical           1     1    :mod:`~eomgen.model.joints.helical`
 fixed             0     0    :mod:`~eomgen.model.joints.fixed`
 spherical         4     3    :mod:`~eomgen.model.joints.spherical`
 planar            4     3    :mod:`~eomgen.model.joints.planar`
 universal         2     2    :mod:`~eomgen.model.joints.universal`
 free flyer        7     6    :mod:`~eomgen.model.joints.free_flyer`
===============  ====  ====  =====================================================

:mod:`~eomgen.model.joints.base` says what a kind is (frames, signs, and how the algorithms
see it); :mod:`~eomgen.model.joints.lie` holds the rotations and rigid motions they share.
"""

from __future__ import annotations

from .base import ChainKind, ChartKind, JointKind
from .fixed import FIXED
from .free_flyer import FREE_FLYER
from .helical import HELICAL
from .planar import PLANAR
from .prismatic import PRISMATIC
from .revolute import CONTINUOUS, REVOLUTE
from .spherical import SPHERICAL
from .universal import UNIVERSAL

#: Every kind by its name. :class:`eomgen.model.JointType` has a member for each kind a
#: description writes (:attr:`JointKind.described`): adding a kind is its module and its line
#: here.
KINDS: dict[str, JointKind] = {kind.name: kind for kind in (
    REVOLUTE, CONTINUOUS, PRISMATIC, FIXED, SPHERICAL, PLANAR, HELICAL, UNIVERSAL, FREE_FLYER)}

__all__ = ["CONTINUOUS", "ChainKind", "ChartKind", "FIXED", "FREE_FLYER", "HELICAL", "JointKind",
           "KINDS", "PLANAR", "PRISMATIC", "REVOLUTE", "SPHERICAL", "UNIVERSAL"]
