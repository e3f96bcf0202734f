"""Solving ``M(q) q̈ = b`` with a Cholesky factorisation, a condition estimate and a warning.

The code is :mod:`eomgen.runtime.cholesky`, which the generated NumPy modules include
verbatim for their ``forward_dynamics`` (they import nothing from eomgen): one copy of these
rules. This module re-exports its public names for eomgen's analyses.

* ``M = L Lᵀ`` by Cholesky; when that fails, M is not (numerically) positive definite and a
  :class:`numpy.linalg.LinAlgError` names the state: a joint that moves no mass, or inertias
  that are not physical. Never a silent NaN.
* A non-finite M or right-hand side (overflow, non-finite input) raises
  :class:`FloatingPointError` naming the state.
* The condition number is estimated from the factor's diagonal,
  ``κ̂ = (max_i L_ii / min_i L_ii)²``. Because the eigenvalues of the triangular L are its
  diagonal entries, ``σ_max(L) ≥ max L_ii`` and ``σ_min(L) ≤ min L_ii``, and
  ``cond₂(M) = cond₂(L)²``: κ̂ is a *lower bound* of cond₂(M), free once L is known. A warning
  is therefore never a false alarm; κ̂ can underestimate (see ``docs/numerics.md`` for how
  much on the hard cases).
  On random robots (``tests/reference.random_robot``, 260 states) cond₂/κ̂ had median 2,
  90th percentile 6 and maximum 130. So where κ̂ exceeds :data:`EXACT_FROM` (10⁻⁴ times the
  limit), the exact cond₂ from the eigenvalues of M replaces it: cheap screening, exact
  confirmation.
* When ``cond(M) · ε > 10⁻⁶`` (cond > :data:`CONDITION_LIMIT` ≈ 4.5e9), the solution may have
  lost more than ten of its sixteen digits (forward error ≲ cond(M) · ε relative): an
  :class:`IllConditionedWarning`.
"""

from __future__ import annotations

from ..runtime.cholesky import (CONDITION_LIMIT, EXACT_FROM, IllConditionedWarning,
                               cholesky_solve, condition_estimate, condition_number,
                               ill_conditioned_message)

__all__ = ["CONDITION_LIMIT", "EXACT_FROM", "IllConditionedWarning", "cholesky_solve",
           "condition_estimate", "condition_number", "ill_conditioned_message"]
