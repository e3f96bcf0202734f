"""Task-space (operational-space) quantities of frames from M(q) and the frame Jacobians.

The one NumPy copy of these rules. The NumPy backend includes the text between the
``# --- included`` and ``# --- end of the included text`` markers in every generated module that
exports a task-space function (``operational_space_inertia``, ``operational_space_bias``,
``dynamically_consistent_inverse``; see :func:`included_source`); after the end marker this
module gives :func:`operational_space` its public name for eomgen's own use and tests.

For each frame with world-aligned Jacobian J at its origin (6 × NV, linear rows first, or its
3 linear rows alone) and M = L Lᵀ (Cholesky):

* ``Z = L⁻¹ Jᵀ``, so that ``Zᵀ Z = J M⁻¹ Jᵀ``;
* ``Λ = (J M⁻¹ Jᵀ + damping 1)⁻¹``, formed as ``W ᵀ W`` with ``W = L_A⁻¹``, ``L_A`` the
  Cholesky factor of ``A = Zᵀ Z + damping 1`` (so Λ is symmetric to the last bit);
* ``J̄ = M⁻¹ Jᵀ Λ = L⁻ᵀ Z Λ``, the dynamically consistent inverse (J J̄ = 1 at damping 0).

At damping 0 a frame whose ``A`` has a Cholesky pivot at most ``1e-10`` times its largest
diagonal entry (cond ≳ 1e10: a kinematic singularity, or a direction no joint moves the frame
in) raises
:class:`numpy.linalg.LinAlgError` naming the frame and the state: Λ does not exist there.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

_MARKER = "# --- included in the generated NumPy modules from here on ---\n"
_END_MARKER = "# --- end of the included text: public names for eomgen's own use ---\n"


def included_source() -> str:
    """The text the NumPy backend includes in a generated module (between the markers)."""
    text = Path(__file__).read_text(encoding="utf-8")
    return text[text.index(_MARKER) + len(_MARKER):text.index(_END_MARKER)].strip("\n")


# --- included in the generated NumPy modules from here on ---
#: At damping 0, J M^-1 J^T counts as singular when a pivot of its Cholesky factorisation is
#: at most this times its largest diagonal entry (cond >~ 1e10), as in the fast module and as
#: constrained_forward_dynamics' contact rows.
_TASK_SINGULAR = 1e-10


def _frame_selection(frames, names, who=""):
    """(indices, one) of the frames asked for: ``frames`` None (every one of ``names``), a name
    or index (``one``: the result drops the frame axis), or a sequence of names and indices."""
    one = isinstance(frames, (str, int, np.integer))
    chosen = range(len(names)) if frames is None else [frames] if one else list(frames)
    indices = []
    for frame in chosen:
        if isinstance(frame, str):
            if frame not in names:
                raise ValueError(f"{who}unknown frame {frame!r} (FRAME_NAMES: "
                                 f"{', '.join(names)})")
            indices.append(list(names).index(frame))
        elif -len(names) <= int(frame) < len(names):
            indices.append(int(frame) % len(names))
        else:
            raise ValueError(f"{who}frame index {frame} out of range for {len(names)} frames")
    return np.array(indices, dtype=int), one


def _operational_space(M, J, damping=0.0, linear=False, names=None, single=False, who=""):
    """Lambda and Jbar of every frame at every state.

    M: (N, n, n) mass matrices; J: (N, 6 nf, n) world-aligned frame Jacobians, [linear;
    angular] per frame. Returns Lambda (N, nf, r, r) = (J M^-1 J^T + damping 1)^-1 and Jbar
    (N, nf, n, r) = M^-1 J^T Lambda, r = 3 with ``linear`` (the linear rows only), else 6.
    ``names`` (the frames) and ``single`` word the errors, ``who`` prefixes them.

    Raises ValueError for a damping not finite or < 0, FloatingPointError when M or J is not
    finite, numpy.linalg.LinAlgError when M is not positive definite or, at damping 0, when
    J M^-1 J^T of a frame is singular (see _TASK_SINGULAR); with damping > 0, when
    J M^-1 J^T + damping 1 is not positive definite (damping lost in rounding)."""
    damping = float(damping)
    if not (np.isfinite(damping) and damping >= 0.0):
        raise ValueError(f"{who}damping must be a finite number >= 0, got {damping!r}")
    M = np.asarray(M, dtype=float)
    J = np.asarray(J, dtype=float)
    N, rows, n = J.shape
    nf = rows // 6
    J = J.reshape(N, nf, 6, n)[:, :, :3] if linear else J.reshape(N, nf, 6, n)
    r = J.shape[2]
    finite = np.all(np.isfinite(M), axis=(1, 2)) & np.all(np.isfinite(J), axis=(1, 2, 3))
    if not np.all(finite):
        raise FloatingPointError(f"{who}M(q) or a frame Jacobian is not finite"
                                 f"{_task_at(int(np.argmin(finite)), single)} (overflow, or "
                                 "non-finite input)")
    try:
        L = np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        bad = next((k for k in range(N) if np.any(np.linalg.eigvalsh(M[k]) <= 0)), 0)
        raise np.linalg.LinAlgError(
            f"{who}M(q) is not positive definite{_task_at(bad, single)}: a joint moves no mass "
            "or inertia, or the inertias are not physical") from None
    Lb = np.broadcast_to(L[:, np.newaxis], (N, nf, n, n))
    Z = np.linalg.solve(Lb, np.swapaxes(J, -1, -2))              # L^-1 J^T: (N, nf, n, r)
    A = np.swapaxes(Z, -1, -2) @ Z
    A = 0.5 * (A + np.swapaxes(A, -1, -2)) + damping * np.eye(r)
    LA, bad = _task_cholesky(A, 0.0 if damping > 0.0 else _TASK_SINGULAR)
    if bad is not None:
        k, f = bad
        if damping > 0.0:
            raise np.linalg.LinAlgError(
                f"{who}J M^-1 J^T + damping 1 is not positive definite{_task_at(k, single)} "
                f"(damping {damping:g} is lost in rounding); use a larger damping")
        frame = f"frame {names[f]!r}" if names is not None else f"frame {f}"
        raise np.linalg.LinAlgError(
            f"{who}J M^-1 J^T of {frame} ({r}x{r}) is singular{_task_at(k, single)} (a "
            "Cholesky pivot <= 1e-10 of its largest diagonal entry, cond >~ 1e10: a kinematic "
            "singularity, or a direction no joint moves the frame in); use damping > 0")
    W = np.linalg.solve(LA, np.broadcast_to(np.eye(r), A.shape))  # L_A^-1
    Lam = np.swapaxes(W, -1, -2) @ W
    Jbar = np.linalg.solve(np.swapaxes(Lb, -1, -2), Z) @ Lam       # L^-T Z Lambda
    return Lam, Jbar


def _task_cholesky(A, tol):
    """(L, None) with A = L L^T for the (N, nf, r, r) matrices A, or (None, (state, frame)) of
    the first whose Cholesky pivot (before its square root) is not above ``tol`` times its
    largest diagonal entry (the rule of the fast module's task_space_frame)."""
    N, nf, r, _ = A.shape
    L = np.zeros_like(A)
    scale = tol * np.max(np.diagonal(A, axis1=-2, axis2=-1), axis=-1, initial=0.0)
    for j in range(r):
        d = A[..., j, j] - np.einsum("bfk,bfk->bf", L[..., j, :j], L[..., j, :j])
        failed = ~(d > scale)
        if np.any(failed):
            k, f = np.unravel_index(int(np.argmax(failed)), failed.shape)
            return None, (int(k), int(f))
        L[..., j, j] = np.sqrt(d)
        L[..., j + 1:, j] = (A[..., j + 1:, j] - np.einsum(
            "bfik,bfk->bfi", L[..., j + 1:, :j], L[..., j, :j])) / L[..., j, j][..., None]
    return L, None


def _task_at(k, single):
    return "" if single else f" at state {k}"


# --- end of the included text: public names for eomgen's own use ---
#: J M^-1 J^T counts as singular at damping 0 at a Cholesky pivot below this times its
#: largest diagonal entry.
TASK_SINGULAR = _TASK_SINGULAR
operational_space = _operational_space
frame_selection = _frame_selection

__all__ = ["TASK_SINGULAR", "frame_selection", "included_source", "operational_space"]
