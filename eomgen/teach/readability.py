"""Deprecated: moved to :mod:`eomgen.present.readability` (the regrouping is shared by the
display, the notebook, the LaTeX document and the handout). This module re-exports its public
names so that old imports keep working; import from :mod:`eomgen.present.readability` instead.
"""

from ..present.readability import (  # noqa: F401  (deprecated re-exports)
    NamedFactor, by_mass, by_trig, common_christoffel_factors, common_monomial, group_by_factor,
    in_terms_of, mass_grouped, perfect_power, readable_sum, trig_grouped,
)
