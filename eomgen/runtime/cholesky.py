"""Solving ``M(q) q̈ = b`` with a Cholesky factorisation, a condition number and a warning.

The one NumPy copy of these rules. The NumPy backend includes the text between the
``# --- included`` and ``# --- end of the included text`` markers in every generated module that
exports ``forward_dynamics`` (see :func:`included_source`), where its names are private to the
generated module; after the end marker this module gives them their public names
(:data:`CONDITION_LIMIT`, :func:`cholesky_solve`, ...), which eomgen's own solvers use
(:mod:`eomgen.analysis.conditioning`, and so ``simulate``, ``verify``, ``lambdify``):

* ``M = L Lᵀ`` by Cholesky; when that fails, M is not (numerically) positive definite and a
  :class:`numpy.linalg.LinAlgError` names the state: a joint that moves no mass, or inertias
  that are not physical. Never a silent NaN.
* A non-finite M or right-hand side (overflow, non-finite input) raises
  :class:`FloatingPointError` naming the state.
* The condition number is estimated from the factor's diagonal, ``κ̂ = (max L_ii / min
  L_ii)²``: a lower bound of cond₂(M) (the eigenvalues of the triangular L are its diagonal,
  and cond₂(M) = cond₂(L)²), free once L is known. Where κ̂ exceeds ``_EXACT_FROM`` (10⁻⁴ of
  the limit), the exact cond₂ from the eigenvalues of M replaces it.
* When ``cond(M) · ε > 10⁻⁶`` (``_CONDITION_LIMIT`` ≈ 4.5e9) the solution may have lost more
  than ten of its sixteen digits: an :class:`IllConditionedWarning`.
"""

from __future__ import annotations

import warnings as _warnings
from pathlib import Path

import numpy as np

_MARKER = "# --- included in the generated NumPy modules from here on ---\n"
_END_MARKER = "# --- end of the included text: public names for eomgen's own use ---\n"


def included_source() -> str:
    """The text the NumPy backend includes in a generated module (between the markers)."""
    text = Path(__file__).read_text(encoding="utf-8")
    return text[text.index(_MARKER) + len(_MARKER):text.index(_END_MARKER)].strip("\n")


# --- included in the generated NumPy modules from here on ---
#: forward_dynamics warns when the condition number of M exceeds this (cond(M) * eps > 1e-6).
_CONDITION_LIMIT = 1e-6 / np.finfo(float).eps
#: Above this estimate the exact condition number is computed (eigenvalues of M).
_EXACT_FROM = 1e-4 * _CONDITION_LIMIT


class IllConditionedWarning(RuntimeWarning):
    """M(q) is so ill-conditioned (cond(M) * eps > 1e-6) that qdd may carry a relative error
    up to about cond(M) * eps."""


def _condition_estimate(L):
    """(max L_ii / min L_ii)^2 of Cholesky factors L, (n, n) or (N, n, n): a lower bound of
    the 2-norm condition number of L L^T; 1 for n = 0."""
    d = np.abs(np.diagonal(L, axis1=-2, axis2=-1))
    if d.shape[-1] == 0:
        return np.ones(d.shape[:-1])
    with np.errstate(divide="ignore"):
        return (np.max(d, axis=-1) / np.min(d, axis=-1)) ** 2


def _condition_number(M, L):
    """The 2-norm condition number of M (n, n) or (N, n, n) with Cholesky factors L: the
    estimate, replaced by the exact value (eigenvalues) where it exceeds _EXACT_FROM."""
    condition = np.array(_condition_estimate(L), dtype=float)
    close = condition > _EXACT_FROM
    if np.any(close):
        eigenvalues = np.linalg.eigvalsh(M[close] if M.ndim == 3 else M)
        exact = eigenvalues[..., -1] / np.maximum(eigenvalues[..., 0], np.finfo(float).tiny)
        condition[close] = np.maximum(condition[close], exact)
    return condition


def _ill_conditioned_message(condition, where="", who=""):
    """The IllConditionedWarning text (``who``: the function's name and a colon, or empty)."""
    return (f"{who}M(q) is ill-conditioned{where}: cond(M) >= {condition:.2e}, so qdd may "
            f"carry a relative error up to about cond(M)*eps = "
            f"{condition * np.finfo(float).eps:.1e}")


def _cholesky_solve(M, b, warn=True, who="", stacklevel=1):
    """Solve M x = b for symmetric positive definite M: one system ((n, n), (n,)) or a batch
    ((N, n, n), (N, n)). Returns (x, condition), condition the condition number of each M.

    Raises numpy.linalg.LinAlgError when M is not positive definite and FloatingPointError when
    M or b is not finite, naming the first such state of a batch; warns IllConditionedWarning
    (when ``warn``) when the condition number exceeds _CONDITION_LIMIT. ``who`` prefixes the
    messages (e.g. "forward_dynamics: ")."""
    M = np.asarray(M, dtype=float)
    b = np.asarray(b, dtype=float)
    single = M.ndim == 2
    Mb, bb = (M[np.newaxis], b[np.newaxis]) if single else (M, b)
    finite = np.all(np.isfinite(Mb), axis=(1, 2)) & np.all(np.isfinite(bb), axis=1)
    if not np.all(finite):
        raise FloatingPointError(
            f"{who}M(q) or the right-hand side (C(q, qd) qd + g(q), tau) is not finite"
            f"{_at(int(np.argmin(finite)), single)} (overflow, or non-finite input)")
    try:
        L = np.linalg.cholesky(Mb)
    except np.linalg.LinAlgError:
        raise np.linalg.LinAlgError(
            f"{who}M(q) is not positive definite{_at(_not_positive_definite(Mb), single)}: a "
            "joint moves no mass or inertia, or the inertias are not physical") from None
    condition = _condition_number(Mb, L)
    k = int(np.argmax(condition)) if condition.size else 0
    if warn and condition.size and condition[k] > _CONDITION_LIMIT:
        _warnings.warn(_ill_conditioned_message(condition[k], _at(k, single), who),
                       IllConditionedWarning, stacklevel=stacklevel + 1)
    n = Mb.shape[-1]
    y = np.zeros_like(bb)
    for i in range(n):  # L y = b, then L^T x = y: one pass over the batch per row
        y[:, i] = (bb[:, i] - np.einsum("nj,nj->n", L[:, i, :i], y[:, :i])) / L[:, i, i]
    x = np.zeros_like(bb)
    for i in reversed(range(n)):
        x[:, i] = (y[:, i] - np.einsum("nj,nj->n", L[:, i + 1:, i], x[:, i + 1:])) / L[:, i, i]
    return (x[0], condition[0]) if single else (x, condition)


def _at(k, single):
    return "" if single else f" at state {k}"


def _not_positive_definite(M):
    """The first of the (N, n, n) matrices M whose Cholesky factorisation fails."""
    for k in range(M.shape[0]):
        try:
            np.linalg.cholesky(M[k])
        except np.linalg.LinAlgError:
            return k
    return 0


# --- end of the included text: public names for eomgen's own use ---
#: forward_dynamics warns when the condition number of M exceeds this (cond(M) * eps > 1e-6).
CONDITION_LIMIT = _CONDITION_LIMIT
#: Above this estimate the exact condition number is computed (eigenvalues of M).
EXACT_FROM = _EXACT_FROM
condition_estimate = _condition_estimate
condition_number = _condition_number
ill_conditioned_message = _ill_conditioned_message
cholesky_solve = _cholesky_solve

__all__ = ["CONDITION_LIMIT", "EXACT_FROM", "IllConditionedWarning", "cholesky_solve",
           "condition_estimate", "condition_number", "ill_conditioned_message",
           "included_source"]
