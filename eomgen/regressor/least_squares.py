"""The regressor at measured states, and the ordinary least squares of β on it.

:func:`observation_matrix` stacks the base regressor Y_base over samples into W;
:func:`normalised_condition` says how well W excites the parameters; :func:`identify` solves
``min |W β − τ|``. These are the pieces of identification that need only the regressor: the
workflow around them (CSV data, Gautier's weighted least squares, the physically consistent
fit, excitation trajectories) is :mod:`eomgen.identification`, which imports them from here
(identification is built on the regressor, never the other way round).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np

from .derive import Regressor


def observation_matrix(reg: Regressor, columns: Sequence[int], q, qd, qdd,
                       values: Mapping | None = None) -> np.ndarray:
    """W = the base regressor stacked over the samples, (N n, b), sample-major: rows
    ``k n … k n + n − 1`` are sample k's joints (so joint j's rows are ``W[j::n]``)."""
    f = reg.compiled(values, program=reg.base_program(list(columns)))
    q, qd, qdd = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (q, qd, qdd))
    if len(q) == 0:
        return np.zeros((0, len(columns)))
    return np.vstack([f(*row)["Y_base"] for row in zip(q, qd, qdd)])


def normalised_condition(W: np.ndarray) -> float:
    """Condition number of W with its columns scaled to unit norm (zero columns left out of
    the scaling): how well the samples excite the parameters, whatever their units."""
    norms = np.linalg.norm(W, axis=0)
    return float(np.linalg.cond(W / np.where(norms > 0, norms, 1.0)))


@dataclass(frozen=True)
class Identification:
    """Least-squares estimate of the base parameters from measurements.

    Attributes
    ----------
    beta:
        Estimated β, (b,), in the order of the base used.
    std:
        Standard deviations of β from the residual (σ² (WᵀW)⁻¹, σ² = ‖τ − W β‖² / (rows − b)).
    rms:
        Root mean square of the residual τ − W β [N m or N].
    condition:
        Condition number of the column-normalised observation matrix W (a measure of how well
        the trajectory excites the base parameters).
    """

    beta: np.ndarray
    std: np.ndarray
    rms: float
    condition: float


def identify(reg: Regressor, base, q, qd, qdd, tau, values: Mapping | None = None
             ) -> Identification:
    """Estimate β by ordinary least squares, ``min |W β − τ|`` with W the base regressor
    stacked over the samples (:func:`observation_matrix`). Gautier's weighted least squares,
    CSV data and the physically consistent fit are in :mod:`eomgen.identification`, which
    builds on this module.

    Parameters
    ----------
    reg:
        The regressor.
    base:
        A :class:`BaseParameters` or :class:`SymbolicBase` (its ``base`` columns are used).
    q, qd, qdd, tau:
        (N, n) arrays of joint positions, velocities, accelerations and measured efforts, in
        JOINT_NAMES order (SI units); with quaternion joints q is (N, NQ), in
        CONFIGURATION_NAMES order, and qd, qdd are v and v̇.
    values:
        Geometry parameter values overriding the model's defaults.

    Raises
    ------
    ValueError
        When the arrays are not (N, n) or there are fewer rows N n than base parameters.
    """
    arrays = [np.atleast_2d(np.asarray(x, dtype=float)) for x in (q, qd, qdd, tau)]
    nq = len(reg.q)
    if (arrays[0].shape != (arrays[1].shape[0], nq)
            or any(a.shape != arrays[1].shape or a.shape[1] != reg.n for a in arrays[1:])):
        shape = f"(N, {reg.n})" if nq == reg.n else f"(N, {nq}) and qd, qdd, tau (N, {reg.n})"
        raise ValueError(f"q, qd, qdd and tau must have shape {shape}")
    columns = list(base.base)
    if arrays[1].size < len(columns):
        raise ValueError(f"{arrays[0].size} equations for {len(columns)} base parameters")
    W = observation_matrix(reg, columns, *arrays[:3], values=values)
    y = arrays[3].reshape(-1)
    beta, *_ = np.linalg.lstsq(W, y, rcond=None)
    residual = y - W @ beta
    dof = max(W.shape[0] - W.shape[1], 1)
    sigma2 = float(residual @ residual) / dof
    cov = sigma2 * np.linalg.pinv(W.T @ W)
    return Identification(beta, np.sqrt(np.clip(np.diag(cov), 0, None)),
                          float(np.sqrt(np.mean(residual ** 2))), normalised_condition(W))
