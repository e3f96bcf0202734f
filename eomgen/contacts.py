"""Deprecated path: rigid contacts, numerically, moved to :mod:`eomgen.numeric.contacts`
(:class:`~eomgen.numeric.contacts.ContactDynamics`, :func:`~eomgen.numeric.contacts.rotation_log`,
...; the conventions are in its docstring), and the :class:`~eomgen.model.Contact` data with
``POINT`` and ``SURFACE`` to the model (:mod:`eomgen.model`). The names stay importable from here,
the path the docs name (``eomgen.contacts.ContactDynamics``).
"""

from __future__ import annotations

from .model import POINT, SURFACE, Contact
from .numeric.contacts import RANK_TOLERANCE, ContactDynamics, derived_mass_and_bias, rotation_log

__all__ = ["POINT", "SURFACE", "RANK_TOLERANCE", "Contact", "ContactDynamics",
           "derived_mass_and_bias", "rotation_log"]
