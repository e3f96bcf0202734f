"""Estimating the base parameters from an observation matrix: Gautier's weighted least squares
(:func:`weighted_least_squares`, :class:`Estimate`) and the physically consistent fit, every
body's pseudo-inertia positive semi-definite (:func:`physical_fit`, an SDP that needs cvxpy)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import IdentificationError, one_line
from ..regressor.least_squares import normalised_condition


@dataclass(frozen=True)
class Estimate:
    """A weighted least-squares estimate of the base parameters.

    Attributes
    ----------
    beta : (b,) array
        The estimate β̂.
    std : (b,) array
        Standard deviations, the square roots of the diagonal of σ̃² (W̃ᵀW̃)⁻¹.
    sigma : (n,) array
        Per-joint standard deviation of the effort error, σ_j, that weighted joint j's rows.
    rms : (n,) array
        Per-joint RMS of the residual τ − W β̂ [N m or N].
    condition : float
        Condition number of the column-normalised (unweighted) W.
    predicted : (N, n) array
        W β̂, the efforts the estimate predicts.
    """

    beta: np.ndarray
    std: np.ndarray
    sigma: np.ndarray
    rms: np.ndarray
    condition: float
    predicted: np.ndarray

    @property
    def relative_std(self) -> np.ndarray:
        """100 std / |β̂| [%] (inf where β̂ is 0)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(self.beta != 0, 100 * self.std / np.abs(self.beta), np.inf)


def weighted_least_squares(W: np.ndarray, tau: np.ndarray, source: str = "<data>"
                           ) -> Estimate:
    """Gautier's weighted least squares of ``τ = W β``.

    First each joint's rows alone (``W_j = W[j::n]``, ``τ_j``) are solved by ordinary least
    squares; σ_j² = |τ_j − W_j β_j|² / (N − rank W_j) estimates that joint's effort noise
    (Gautier & Poignet 2001). Joint j's rows are then divided by σ_j and the whole system
    solved: β̂ = argmin |W̃ β − τ̃|, with covariance σ̃² (W̃ᵀW̃)⁻¹, σ̃² = |τ̃ − W̃ β̂|² /
    (N n − b). Noise-free data (all σ_j zero) are weighted equally; a σ_j below 1e-12 of the
    largest is raised to that.

    Parameters
    ----------
    W : (N n, b) array
        Observation matrix (:func:`observation_matrix`).
    tau : (N, n) array
        Measured efforts.
    source:
        Named in error messages.

    Raises
    ------
    IdentificationError
        Fewer equations than base parameters, or W of lower rank than b (the samples do not
        excite every base parameter).
    """
    tau = np.asarray(tau, dtype=float)
    N, n = tau.shape
    b = W.shape[1]
    if N * n < b or N * n == 0:
        raise IdentificationError(f"{source}: {N} samples give {N * n} equations for {b} base "
                                  "parameters; record more samples")
    y = tau.reshape(-1)
    rank = np.linalg.matrix_rank(W / np.where(np.linalg.norm(W, axis=0) > 0,
                                               np.linalg.norm(W, axis=0), 1.0), tol=1e-10)
    if rank < b:
        raise IdentificationError(f"{source}: the {N} samples excite only {rank} of the {b} base "
                                  "parameters (rank of the observation matrix); record more "
                                  "samples or a richer trajectory (eomgen excite)")
    sigma = np.zeros(n)
    for j in range(n):
        Wj, yj = W[j::n], tau[:, j]
        sol, _, rank_j, _ = np.linalg.lstsq(Wj, yj, rcond=None)
        r = yj - Wj @ sol
        sigma[j] = math.sqrt(float(r @ r) / max(N - rank_j, 1))
    if sigma.max() == 0:
        sigma[:] = 1.0
    sigma = np.maximum(sigma, 1e-12 * sigma.max())
    weight = np.tile(1.0 / sigma, N)
    Wt, yt = W * weight[:, None], y * weight
    Q, R = np.linalg.qr(Wt)
    beta = np.linalg.solve(R, Q.T @ yt)
    rt = yt - Wt @ beta
    s2 = float(rt @ rt) / max(N * n - b, 1)
    Rinv = np.linalg.inv(R)
    std = np.sqrt(s2 * np.sum(Rinv ** 2, axis=1))
    predicted = (W @ beta).reshape(N, n)
    rms = np.sqrt(np.mean((tau - predicted) ** 2, axis=0))
    return Estimate(beta, std, sigma, rms, normalised_condition(W), predicted)


def pseudo_inertia(pi10) -> np.ndarray:
    """The 4 × 4 pseudo-inertia J of one body (Wensing, Kim & Slotine 2017).

    ``pi10 = (m, MX, MY, MZ, XX, XY, YY, XZ, YZ, ZZ)``, inertia Ī about the body origin::

        J = [[Σ, h], [hᵀ, m]],   Σ = ½ tr(Ī) 1 − Ī = ∫ r rᵀ dm,   h = m c

    J ⪰ 0 exactly when some non-negative mass distribution has these parameters.

    >>> J = pseudo_inertia([2.0, 0.2, 0, 0, 0, 0, 0.02, 0, 0, 0.02])  # 2 kg at x = 0.1 m
    >>> J.diagonal().round(12).tolist(), bool(abs(np.linalg.eigvalsh(J)[0]) < 1e-15)  # singular
    ([0.02, 0.0, 0.0, 2.0], True)
    """
    m, hx, hy, hz, xx, xy, yy, xz, yz, zz = pi10
    I = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]], dtype=float)
    J = np.zeros((4, 4))
    J[:3, :3] = 0.5 * np.trace(I) * np.eye(3) - I
    J[:3, 3] = J[3, :3] = (hx, hy, hz)
    J[3, 3] = m
    return J


def base_map(base, p: int) -> np.ndarray:
    """E (b × p) with β(π) = E π, from ``base.beta`` at the unit vectors."""
    return np.column_stack([base.beta(np.eye(p)[k]) for k in range(p)])


@dataclass(frozen=True)
class PhysicalFit:
    """A physically consistent estimate: standard parameters π whose pseudo-inertias are all
    positive semi-definite, fitted to the same weighted least squares.

    Attributes
    ----------
    pi : (p,) array
        Standard parameters (PARAMETER_NAMES order; not unique where β does not fix them).
    beta : (b,) array
        β(π).
    min_eigenvalues : (n,) array
        Smallest eigenvalue of each body's pseudo-inertia [kg m²] (≥ 0 up to solver tolerance).
    rms : (n,) array
        Per-joint RMS of τ − W β.
    predicted : (N, n) array
    status : str
        The solver's status.
    """

    pi: np.ndarray
    beta: np.ndarray
    min_eigenvalues: np.ndarray
    rms: np.ndarray
    predicted: np.ndarray
    status: str


def physical_fit(reg, base, W: np.ndarray, tau: np.ndarray, sigma: np.ndarray,
                 source: str = "<data>") -> PhysicalFit:
    """Weighted least squares over π subject to every body's pseudo-inertia J_k(π) ⪰ 0 (and
    viscous and Coulomb friction coefficients ≥ 0), as a semi-definite program in cvxpy.

    Minimises |R E π − Qᵀ τ̃|² (written as one Euclidean norm, scaled so that the largest
    singular value of R E is 1) where W̃ = Q R is the weighted observation matrix (rows of
    joint j divided by ``sigma[j]``), E the map β = E π (:func:`base_map`); a ridge
    1e-8 s_min² |π|² (s_min the smallest singular value of R E) keeps the parts of π that β
    does not fix bounded while moving the fit by no more than 1e-8 of its weakest direction.
    Clarabel solves it when installed (gap and feasibility tolerances 1e-10), else SCS.

    Raises
    ------
    IdentificationError
        When cvxpy is missing or the solver fails.
    """
    try:
        import cvxpy as cp  # an optional dependency (eomgen[identify])
    except ImportError:
        raise IdentificationError("the physically consistent fit needs cvxpy: "
                                  "pip install 'eomgen[identify]'") from None
    tau = np.asarray(tau, dtype=float)
    N, n = tau.shape
    weight = np.tile(1.0 / np.asarray(sigma, dtype=float), N)
    Q, R = np.linalg.qr(W * weight[:, None])
    z = Q.T @ (tau.reshape(-1) * weight)
    E = base_map(base, reg.p)
    A = R @ E
    singular = np.linalg.svd(A, compute_uv=False)
    if singular[0] > 0:  # the same minimiser, numbers near 1 for the solver
        A, z, singular = A / singular[0], z / singular[0], singular / singular[0]
    ridge = 1e-8 * float(singular[singular > 0].min() if np.any(singular > 0) else 1.0) ** 2
    pi = cp.Variable(reg.p)
    constraints = []
    for k in range(reg.n):
        m, hx, hy, hz, xx, xy, yy, xz, yz, zz = (pi[10 * k + i] for i in range(10))
        half = 0.5 * (xx + yy + zz)
        J = cp.bmat([[half - xx, -xy, -xz, hx],
                     [-xy, half - yy, -yz, hy],
                     [-xz, -yz, half - zz, hz],
                     [hx, hy, hz, m]])
        constraints.append(0.5 * (J + J.T) >> 0)
    for term, offset in zip(reg.actuators, range(10 * reg.n, reg.p, reg.n)):
        if term in ("viscous", "coulomb", "armature"):
            constraints.append(pi[offset:offset + reg.n] >= 0)
    # |A π − z|² + ridge |π|² as one Euclidean norm (a second-order cone): the same
    # minimiser, and the solver's tolerance then bounds the residual, not its square
    stacked = np.vstack([A, math.sqrt(ridge) * np.eye(reg.p)])
    target = np.concatenate([z, np.zeros(reg.p)])
    problem = cp.Problem(cp.Minimize(cp.norm(stacked @ pi - target, 2)), constraints)
    solver = cp.CLARABEL if "CLARABEL" in cp.installed_solvers() else cp.SCS
    try:
        tight = ({"tol_gap_abs": 1e-10, "tol_gap_rel": 1e-10, "tol_feas": 1e-10}
                 if solver == cp.CLARABEL else {"eps": 1e-9})
        problem.solve(solver=solver, **tight)
    except cp.error.SolverError as exc:
        raise IdentificationError(one_line(f"{source}: physically consistent fit: {exc}")) from None
    if problem.status not in ("optimal", "optimal_inaccurate") or pi.value is None:
        raise IdentificationError(f"{source}: physically consistent fit: solver status "
                                  f"{problem.status}")
    x = np.asarray(pi.value, dtype=float)
    beta = E @ x
    predicted = (W @ beta).reshape(N, n)
    eig = np.array([np.linalg.eigvalsh(pseudo_inertia(x[10 * k:10 * k + 10]))[0]
                    for k in range(reg.n)])
    rms = np.sqrt(np.mean((tau - predicted) ** 2, axis=0))
    return PhysicalFit(x, beta, eig, rms, predicted, str(problem.status))
