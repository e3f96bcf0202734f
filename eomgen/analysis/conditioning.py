"""Solving ``M(q) q̈ = b`` with a Cholesky factorisation, a condition estimate and a warning.

This is the library twin of the generated ``forward_dynamics`` (``templates/numpy``), which
applies the same rules without importing eomgen:

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

import warnings

import numpy as np

#: ``forward_dynamics`` warns when the condition estimate exceeds this: ``1e-6 / ε``.
CONDITION_LIMIT = 1e-6 / np.finfo(np.float64).eps
#: Above this estimate, the exact condition number is computed (eigenvalues of M).
EXACT_FROM = 1e-4 * CONDITION_LIMIT


class IllConditionedWarning(RuntimeWarning):
    """The mass matrix is so ill-conditioned (cond(M) · ε > 1e-6) that q̈ from a float64 solve
    may carry a relative error up to about cond(M) · ε.

    The generated NumPy modules define a class of the same name (they import nothing from
    eomgen); both are :class:`RuntimeWarning` subclasses, so
    ``warnings.simplefilter("error", RuntimeWarning)`` turns either into an error.
    """


def condition_number(M: np.ndarray, L: np.ndarray) -> np.ndarray:
    """cond₂ of SPD matrices M (n, n) or (N, n, n) with Cholesky factors L: the estimate
    :func:`condition_estimate`, replaced by the exact value where it exceeds
    :data:`EXACT_FROM` (inf when the smallest eigenvalue is not positive)."""
    condition = np.array(condition_estimate(L), dtype=float)
    close = condition > EXACT_FROM
    if np.any(close):
        eigenvalues = np.linalg.eigvalsh(M[close] if M.ndim == 3 else M)
        exact = eigenvalues[..., -1] / np.maximum(eigenvalues[..., 0], np.finfo(float).tiny)
        condition[close] = np.maximum(condition[close], exact)
    return condition


def condition_estimate(L: np.ndarray) -> np.ndarray:
    """``(max_i L_ii / min_i L_ii)²`` of Cholesky factors (n, n) or (N, n, n): a lower bound of
    cond₂(L Lᵀ) (see the module docstring); 1 for n = 0."""
    d = np.abs(np.diagonal(L, axis1=-2, axis2=-1))
    if d.shape[-1] == 0:
        return np.ones(d.shape[:-1])
    with np.errstate(divide="ignore"):
        return (d.max(axis=-1) / d.min(axis=-1)) ** 2


def cholesky_solve(M: np.ndarray, b: np.ndarray, warn: bool = True
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Solve ``M x = b`` for symmetric positive definite M, one system or a batch.

    Parameters
    ----------
    M : (n, n) or (N, n, n) array
    b : (n,) or (N, n) array
    warn : bool
        Warn (:class:`IllConditionedWarning`) when the condition estimate exceeds
        :data:`CONDITION_LIMIT`.

    Returns
    -------
    x : array shaped like b
    condition : float array, () or (N,)
        The condition number of each system (:func:`condition_number`).

    Raises
    ------
    numpy.linalg.LinAlgError
        M is not positive definite (names the first such state of a batch).
    FloatingPointError
        M or b holds NaN or inf (names the first such state).
    """
    M = np.asarray(M, dtype=float)
    b = np.asarray(b, dtype=float)
    single = M.ndim == 2
    Mb, bb = (M[None], b[None]) if single else (M, b)
    finite = np.isfinite(Mb).all(axis=(1, 2)) & np.isfinite(bb).all(axis=1)
    if not finite.all():
        k = int(np.argmin(finite))
        raise FloatingPointError(f"M(q) or the right-hand side is not finite{_at(k, single)} "
                                 "(overflow, or non-finite input)")
    try:
        L = np.linalg.cholesky(Mb)
    except np.linalg.LinAlgError:
        k = _first_not_positive_definite(Mb)
        raise np.linalg.LinAlgError(
            f"M(q) is not positive definite{_at(k, single)}: a joint moves no mass or "
            "inertia, or the inertias are not physical") from None
    condition = condition_number(Mb, L)
    y = np.linalg.solve(L, bb[..., None])
    x = np.linalg.solve(np.swapaxes(L, -1, -2), y)[..., 0]
    worst = int(np.argmax(condition)) if condition.size else 0
    if warn and condition.size and condition[worst] > CONDITION_LIMIT:
        warnings.warn(ill_conditioned_message(float(condition[worst]), _at(worst, single)),
                      IllConditionedWarning, stacklevel=2)
    return (x[0], condition[0]) if single else (x, condition)


def ill_conditioned_message(condition: float, where: str = "") -> str:
    eps = np.finfo(np.float64).eps
    return (f"M(q) is ill-conditioned{where}: cond(M) >= {condition:.2e}, so q̈ may carry a "
            f"relative error up to about cond(M)·ε = {condition * eps:.1e}")


def _at(k: int, single: bool) -> str:
    return "" if single else f" at state {k}"


def _first_not_positive_definite(M: np.ndarray) -> int:
    for k in range(M.shape[0]):
        try:
            np.linalg.cholesky(M[k])
        except np.linalg.LinAlgError:
            return k
    return 0  # pragma: no cover - only called after a failure


__all__ = ["CONDITION_LIMIT", "EXACT_FROM", "IllConditionedWarning", "cholesky_solve",
           "condition_estimate", "condition_number"]
