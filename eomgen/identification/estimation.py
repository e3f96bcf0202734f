"""Identification of the base parameters from measured joint efforts (docs/regressor.md).

The pieces, each a plain function over plain data:

* **Data** (:func:`read_measurements`, :func:`measurements_csv`): a CSV file with a header
  naming its columns after JOINT_NAMES, in any order::

      t, q_<joint>, qd_<joint>, qdd_<joint>, tau_<joint>      (t optional)
      t, q_<joint>, tau_<joint>                               (positions and efforts only)

  SI units (s, rad or m, rad/s or m/s, rad/s² or m/s², N m or N). In the second form q̇ and q̈
  come from :func:`filtered_derivatives`: q and τ through the same zero-phase Butterworth
  low-pass filter (order 4, run forward and backward by ``scipy.signal.sosfiltfilt``), then
  second-order central differences (``numpy.gradient``), then decimation. In the first form
  the columns are used as they are, unless a cut-off is given: then q, q̇, q̈ and τ all go
  through that same filter, trimming and decimation (:func:`filtered_signals`).
* **Estimation** (:func:`weighted_least_squares`): Gautier's weighted least squares, standard
  deviations, condition number; :func:`physical_fit` adds the constraint that every body's
  pseudo-inertia be positive semi-definite (an SDP, needs cvxpy).
* **Excitation** (:class:`FourierTrajectory`, :func:`excitation_trajectory`): a finite
  Fourier series per joint (Swevers et al. 1997) whose coefficients minimise the condition
  number of the base regressor; :func:`simulate_measurements` turns it into data with efforts
  from eomgen.numeric's Newton–Euler, plus noise if asked.

References
----------
M. Gautier, "Dynamic identification of robots with power model", ICRA 1997; M. Gautier and
P. Poignet, "Extended Kalman filtering and weighted least squares dynamic identification of
robot", Control Engineering Practice 9(12), 2001 (the per-joint weights).
J. Swevers, C. Ganseman, D. B. Tükel, J. De Schutter, H. Van Brussel, "Optimal robot excitation
and identification", IEEE Trans. Robotics and Automation 13(5), 1997.
P. M. Wensing, S. Kim, J.-J. E. Slotine, "Linear matrix inequalities for physically consistent
inertial parameter identification: a statistical perspective on the mass distribution",
IEEE Robotics and Automation Letters 3(1), 2018 (arXiv 2017): the pseudo-inertia.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np

from ..errors import IdentificationError, one_line
from ..regressor.least_squares import normalised_condition, observation_matrix  # noqa: F401  (re-exported)


#: Column prefixes of a CSV file, in the order written: positions, velocities, accelerations,
#: efforts, each followed by ``_<joint name>``.
PREFIXES = ("q", "qd", "qdd", "tau")
#: Order of the Butterworth low-pass filter of :func:`filtered_derivatives` (run forward and
#: backward, so the effective order is twice this and the phase is zero).
FILTER_ORDER = 4


# ----------------------------------------------------------------------------------------------
# Data
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Measurements:
    """Samples of a trajectory and the efforts measured along it, JOINT_NAMES order.

    Attributes
    ----------
    joint_names : tuple of str, (n,)
    t : (N,) array or None
        Sample times [s] (None when the file has no ``t`` column).
    q, qd, qdd, tau : (N, n) arrays
        Joint positions, velocities, accelerations and efforts (SI units).
    differentiated : bool
        True when q̇ and q̈ were computed by :func:`filtered_derivatives` (and τ filtered).
    source : str
        Where they came from (file name), for messages.
    cutoff : float or None
        Cut-off frequency [Hz] of the zero-phase low-pass filter the samples went through
        (differentiated, or filtered at a given cut-off), None when they are as read.
    """

    joint_names: tuple[str, ...]
    t: np.ndarray | None
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    differentiated: bool = False
    source: str = "<measurements>"
    cutoff: float | None = None

    @property
    def N(self) -> int:
        """Number of samples."""
        return self.q.shape[0]


def column_names(joint_names: Sequence[str], derivatives: bool = True, time: bool = True
                 ) -> list[str]:
    """The CSV header: ``t`` (if ``time``), then ``q_<joint>`` for every joint, ``qd_``,
    ``qdd_`` (if ``derivatives``) and ``tau_``."""
    prefixes = PREFIXES if derivatives else ("q", "tau")
    return (["t"] if time else []) + [f"{p}_{j}" for p in prefixes for j in joint_names]


def measurements_csv(m: Measurements, derivatives: bool = True) -> str:
    """The CSV text of ``m`` (header :func:`column_names`; shortest round-trip float text, so
    reading it back gives the same numbers). ``derivatives=False`` leaves out q̇ and q̈."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(column_names(m.joint_names, derivatives, m.t is not None))
    blocks = [m.q, m.qd, m.qdd, m.tau] if derivatives else [m.q, m.tau]
    data = np.hstack(([m.t[:, None]] if m.t is not None else []) + blocks)
    for row in data:
        writer.writerow([repr(float(x)) for x in row])
    return out.getvalue()


def read_measurements(path: Path | str, joint_names: Sequence[str],
                      cutoff: float | None = None) -> Measurements:
    """Read a CSV file of measurements (see the module docstring for its columns).

    Parameters
    ----------
    path:
        The CSV file; its first line is the header.
    joint_names:
        JOINT_NAMES of the robot the data belong to (after any scene reduction).
    cutoff:
        Cut-off frequency [Hz] of the zero-phase low-pass filter. When q̇ and q̈ are to be
        computed, default a fifth of the Nyquist frequency (:func:`filtered_derivatives`).
        When the file has them, None (default) uses every column as read; a number filters
        q, q̇, q̈ and τ alike, drops the filter's transients at both ends and decimates
        (:func:`filtered_signals`), which needs the ``t`` column.

    Raises
    ------
    IdentificationError
        For an unreadable file, a missing, unknown or repeated column, a line with the wrong
        number of fields, a field that is not a finite number (naming line and column), times
        that are not increasing and evenly spaced when needed, too few samples to filter, a
        cut-off with no ``t`` column.
    """
    path = Path(path)
    source = str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise IdentificationError(one_line(f"{source}: cannot read the file: "
                                           f"{getattr(exc, 'strerror', None) or exc}")) from None
    rows = list(csv.reader(io.StringIO(text)))
    while rows and not any(field.strip() for field in rows[-1]):
        rows.pop()
    if not rows:
        raise IdentificationError(f"{source}: empty file (expected a header line naming the "
                                  "columns)")
    header = [name.strip() for name in rows[0]]
    differentiate = not any(name.startswith(("qd_", "qdd_")) for name in header)
    expected = column_names(joint_names, derivatives=not differentiate, time=True)
    seen = set()
    for name in header:
        if name in seen:
            raise IdentificationError(one_line(f"{source}: line 1: column {name!r} appears twice"))
        seen.add(name)
        if name not in expected:
            raise IdentificationError(one_line(
                f"{source}: line 1: unknown column {name!r} (expected t, q_<joint>, qd_<joint>, "
                f"qdd_<joint>, tau_<joint> for joints {', '.join(joint_names)})"))
    for name in expected:
        if name not in seen and not (name == "t" and not differentiate):
            raise IdentificationError(one_line(
                f"{source}: line 1: missing column {name!r}"
                + (" (needed to differentiate q: the file has no qd_/qdd_ columns)"
                   if name == "t" else "")))
    data = np.empty((len(rows) - 1, len(header)))
    for i, row in enumerate(rows[1:]):
        line = i + 2
        if len(row) != len(header):
            raise IdentificationError(f"{source}: line {line}: {len(row)} fields, the header "
                                      f"has {len(header)}")
        for c, field in enumerate(row):
            try:
                value = float(field)
            except ValueError:
                value = math.nan
            if not math.isfinite(value):
                raise IdentificationError(one_line(f"{source}: line {line}, column "
                                                   f"{header[c]}: {field.strip()!r} is not a "
                                                   "finite number"))
            data[i, c] = value
    column = {name: data[:, k] for k, name in enumerate(header)}

    def block(prefix):
        return np.column_stack([column[f"{prefix}_{j}"] for j in joint_names]) if joint_names \
            else np.zeros((data.shape[0], 0))

    t = column.get("t")
    q, tau = block("q"), block("tau")
    if not differentiate:
        if cutoff is None:
            return Measurements(tuple(joint_names), t, q, block("qd"), block("qdd"), tau, False,
                                source)
        if t is None:
            raise IdentificationError(f"{source}: line 1: missing column 't' (needed to filter "
                                      f"at the cut-off {cutoff:.6g} Hz)")
        t, (q, qd, qdd, tau), used = filtered_signals(t, (q, block("qd"), block("qdd"), tau),
                                                      cutoff, source)
        return Measurements(tuple(joint_names), t, q, qd, qdd, tau, False, source, used)
    t, q, qd, qdd, tau, used = _filtered_derivatives(t, q, tau, cutoff, source)
    return Measurements(tuple(joint_names), t, q, qd, qdd, tau, True, source, used)


def filtered_derivatives(t, q, tau, cutoff: float | None = None, source: str = "<data>"):
    """q̇, q̈ from sampled q, with q and τ low-pass filtered alike.

    q and τ go through the same Butterworth low-pass filter of order :data:`FILTER_ORDER` run
    forward and backward (``scipy.signal.sosfiltfilt``: zero phase, so no delay between q and
    τ, the parallel filtering of Gautier), cut-off ``cutoff`` [Hz] (default a fifth of the
    Nyquist frequency, fs / 10). The filtered q is differentiated twice by second-order central
    differences (``numpy.gradient``). The signals are extended at both ends by odd reflection
    over three periods of the cut-off frequency (``padlen``), and the samples within those
    three periods of either end, where the filter has not settled, are dropped (interior error
    of q̇ ~1e-4, of q̈ ~1e-3 of their peaks on the excitation trajectories tested). The rest is
    decimated to every ⌊fs / (2 cutoff)⌋-th sample (Gautier's parallel decimation): the
    filtered noise has no content above the cut-off, so samples closer than that are
    correlated and would make the least-squares standard deviations too small.

    Parameters
    ----------
    t : (N,) array, evenly spaced and increasing [s]
    q, tau : (N, n) arrays

    Returns
    -------
    t, q, qd, qdd, tau
        The kept samples (filtered q and τ).

    Raises
    ------
    IdentificationError
        Times not increasing and evenly spaced (to 1e-6 of the step), a cut-off at or above
        the Nyquist frequency, too few samples to filter.
    """
    return _filtered_derivatives(t, q, tau, cutoff, source)[:5]


def _filtered_derivatives(t, q, tau, cutoff, source):
    """:func:`filtered_derivatives`, and the cut-off used."""
    if np.asarray(t).size < 3:
        raise IdentificationError(f"{source}: {np.asarray(t).size} samples; filtered "
                                  "differentiation needs many more (give qd_ and qdd_ columns, "
                                  "or record longer)")
    filtered, keep, dt, cutoff = _lowpass(t, (q, tau), cutoff, source, "filtered differentiation")
    qf, tauf = filtered
    qd = np.gradient(qf, dt, axis=0, edge_order=2)
    qdd = np.gradient(qd, dt, axis=0, edge_order=2)
    t = np.asarray(t, dtype=float)
    return t[keep], qf[keep], qd[keep], qdd[keep], tauf[keep], cutoff


def filtered_signals(t, signals: Sequence, cutoff: float, source: str = "<data>"):
    """Measured signals (q, q̇, q̈, τ as read) through the filter of
    :func:`filtered_derivatives`, all alike.

    The same zero-phase Butterworth low-pass filter (order :data:`FILTER_ORDER`, forward and
    backward, cut-off ``cutoff`` [Hz]) on every signal, so that none is delayed against the
    others and τ = Y(q, q̇, q̈) β still holds up to the filter's effect on the products in Y
    (small when the motion's content lies well below the cut-off); the three cut-off periods
    at each end are dropped and the rest decimated to every ⌊fs / (2 cutoff)⌋-th sample, as in
    :func:`filtered_derivatives`. Nothing is differentiated: q̇ and q̈ stay the measured ones,
    filtered.

    Parameters
    ----------
    t : (N,) array, evenly spaced and increasing [s]
    signals : sequence of (N, n) arrays
    cutoff : float
        [Hz], between 0 and the Nyquist frequency fs / 2.

    Returns
    -------
    t, filtered, cutoff
        The kept times, the kept filtered signals (a tuple in the order given) and the
        cut-off.

    Raises
    ------
    IdentificationError
        As :func:`filtered_derivatives`.
    """
    filtered, keep, _, cutoff = _lowpass(t, signals, cutoff, source, "filtering")
    return np.asarray(t, dtype=float)[keep], tuple(x[keep] for x in filtered), cutoff


def _lowpass(t, signals, cutoff, source, what):
    """Filter ``signals`` (each (N, n)) zero-phase at ``cutoff`` [Hz] (None: fs / 10).
    Returns (filtered signals, slice of the samples to keep, time step, cut-off)."""
    from scipy import signal

    t = np.asarray(t, dtype=float)
    if t.size < 3:
        raise IdentificationError(f"{source}: {t.size} samples; {what} needs many more")
    steps = np.diff(t)
    dt = float(np.mean(steps))
    bad = np.flatnonzero(~(np.abs(steps - dt) <= 1e-6 * abs(dt))) if dt > 0 else [0]
    if len(bad):
        raise IdentificationError(f"{source}: line {int(bad[0]) + 3}, column t: times must "
                                  f"increase by a constant step for {what} (step "
                                  f"{steps[bad[0]]:.6g} s, mean {dt:.6g} s)")
    fs = 1.0 / dt
    cutoff = fs / 10 if cutoff is None else float(cutoff)
    if not 0 < cutoff < fs / 2:
        raise IdentificationError(f"{source}: cut-off {cutoff:.6g} Hz must be between 0 and the "
                                  f"Nyquist frequency {fs / 2:.6g} Hz")
    sos = signal.butter(FILTER_ORDER, cutoff, fs=fs, output="sos")
    # samples per period of the cut-off frequency; the 1e-9 keeps fs / cutoff = 10 from
    # reading as 10.000000000000002 (times from a CSV file)
    period = int(math.ceil(fs / cutoff - 1e-9))
    trim = padlen = 3 * period
    needed = 2 * trim + 3
    if t.size < needed:
        raise IdentificationError(f"{source}: {t.size} samples; {what} at {cutoff:.6g} Hz "
                                  f"needs at least {needed}")
    filtered = tuple(signal.sosfiltfilt(sos, np.asarray(x, dtype=float), axis=0, padlen=padlen)
                     for x in signals)
    keep = slice(trim, t.size - trim, max(1, int(fs / (2 * cutoff) + 1e-9)))
    return filtered, keep, dt, cutoff


# ----------------------------------------------------------------------------------------------
# Estimation
# ----------------------------------------------------------------------------------------------


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
        import cvxpy as cp
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


# ----------------------------------------------------------------------------------------------
# Excitation
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class FourierTrajectory:
    """A finite Fourier series per joint (Swevers et al. 1997), period T = 2π / ω_f::

        q_j(t) = q0_j + Σ_{l=1..L} [ a_jl / (ω_f l) sin(ω_f l t) − b_jl / (ω_f l) cos(ω_f l t) ]

    so that q̇_j = Σ a_jl cos(ω_f l t) + b_jl sin(ω_f l t) and the motion is periodic (every
    period starts in the same state; averaging periods reduces noise).

    Attributes
    ----------
    q0 : (n,) array [rad or m]
    a, b : (n, L) arrays [rad/s or m/s]
    omega : float
        Fundamental angular frequency ω_f [rad/s].
    """

    q0: np.ndarray
    a: np.ndarray
    b: np.ndarray
    omega: float

    def states(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, qd, qdd) at the times ``t`` (N,), each (N, n)."""
        t = np.asarray(t, dtype=float)[:, None, None]
        L = self.a.shape[1]
        w = self.omega * np.arange(1, L + 1)  # (L,)
        s, c = np.sin(w * t), np.cos(w * t)  # (N, 1, L)
        a, b = self.a[None], self.b[None]
        q = self.q0 + np.sum(a / w * s - b / w * c, axis=2)
        qd = np.sum(a * c + b * s, axis=2)
        qdd = np.sum(-a * w * s + b * w * c, axis=2)
        return q, qd, qdd

    def bound(self) -> np.ndarray:
        """The largest possible |q_j(t)| per joint, |q0_j| + Σ_l (|a_jl| + |b_jl|) / (ω_f l)."""
        return np.abs(self.q0) + self._sums(-1)

    def velocity_bound(self) -> np.ndarray:
        """The largest possible |q̇_j(t)| per joint, Σ_l (|a_jl| + |b_jl|)."""
        return self._sums(0)

    def acceleration_bound(self) -> np.ndarray:
        """The largest possible |q̈_j(t)| per joint, Σ_l (|a_jl| + |b_jl|) ω_f l."""
        return self._sums(1)

    def _sums(self, power: int) -> np.ndarray:
        w = self.omega * np.arange(1, self.a.shape[1] + 1)
        return np.sum((np.abs(self.a) + np.abs(self.b)) * w ** power, axis=1)


@dataclass(frozen=True)
class MotionBounds:
    """What an excitation trajectory must respect, per joint (JOINT_NAMES order).

    Attributes
    ----------
    lower, upper : (n,) arrays
        Position range [rad or m]: lower ≤ q_j(t) ≤ upper.
    velocity, acceleration : (n,) arrays
        |q̇_j(t)| ≤ velocity [rad/s or m/s], |q̈_j(t)| ≤ acceleration [rad/s² or m/s²];
        ``inf`` for no bound.
    """

    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray


def motion_bounds(joint_names: Sequence[str], amplitude: float = 1.0,
                  limits: Mapping | None = None, max_velocity: float | None = None,
                  max_acceleration: float | None = None, source: str = "<description>"
                  ) -> MotionBounds:
    """The bounds of :func:`excitation_trajectory` for each joint: the tighter of the options
    and the description's limits.

    Positions: within ±``amplitude`` and within the joint's ``lower``/``upper`` limits when
    given. Velocities: ``max_velocity`` and the joint's ``velocity`` limit. Accelerations:
    ``max_acceleration`` (descriptions have none).

    Parameters
    ----------
    joint_names:
        JOINT_NAMES (after any scene).
    limits:
        Joint name → an object with ``lower``, ``upper``, ``velocity`` attributes (None for
        absent), e.g. :func:`eomgen.parsers.urdf.joint_limits`; joints not in it unbounded.
    source:
        The description, named in errors.

    Raises
    ------
    IdentificationError
        When a joint has no room to move: an empty or zero-width position range (its limits
        outside ±amplitude, or lower ≥ upper), or a velocity or acceleration bound that is not
        positive.
    """
    n = len(joint_names)
    for name, value in (("--amplitude", amplitude), ("--max-velocity", max_velocity),
                        ("--max-acceleration", max_acceleration)):
        if value is not None and not (value > 0):
            raise IdentificationError(f"{name} must be positive, got {value}")
    lower, upper = np.full(n, -float(amplitude)), np.full(n, float(amplitude))
    inf = math.inf
    velocity = np.full(n, inf if max_velocity is None else float(max_velocity))
    acceleration = np.full(n, inf if max_acceleration is None else float(max_acceleration))
    for j, name in enumerate(joint_names):
        limit = (limits or {}).get(name)
        if limit is None:
            continue
        if limit.lower is not None:
            lower[j] = max(lower[j], limit.lower)
        if limit.upper is not None:
            upper[j] = min(upper[j], limit.upper)
        if limit.velocity is not None:
            if not limit.velocity > 0:
                raise IdentificationError(f"{source}: joint '{name}': velocity limit "
                                          f"{limit.velocity:g} leaves no motion to excite")
            velocity[j] = min(velocity[j], limit.velocity)
        if not upper[j] > lower[j]:
            raise IdentificationError(one_line(
                f"{source}: joint '{name}': its limits [{_g(limit.lower)}, {_g(limit.upper)}] "
                f"and ±--amplitude {amplitude:g} leave no room to move (raise --amplitude)"))
    return MotionBounds(lower, upper, velocity, acceleration)


def _g(value: float | None) -> str:
    return "none" if value is None else f"{value:g}"


@dataclass(frozen=True)
class Excitation:
    """The result of :func:`excitation_trajectory`: the trajectory and the condition number of
    the column-normalised base regressor over the optimisation samples before and after."""

    trajectory: FourierTrajectory
    initial_condition: float
    condition: float
    evaluations: int


def excitation_trajectory(reg, base, period: float = 10.0, harmonics: int = 3,
                          amplitude: float = 1.0, samples: int | None = None, seed: int = 0,
                          maxiter: int = 30, values: Mapping | None = None,
                          bounds: MotionBounds | None = None) -> Excitation:
    """Fourier coefficients minimising cond(W_base) (Swevers et al. 1997) within bounds on
    q, q̇ and q̈.

    Variables: q0 and the coefficients a, b of :class:`FourierTrajectory` (n (2 L + 1) of
    them), in boxes that guarantee every bound at every t, not only at samples. With joint j's
    position range [lo, hi] (mid-point m, half-width h), velocity bound V and acceleration
    bound A (``bounds``; default |q_j| ≤ ``amplitude``, no V or A)::

        |q0_j − m| ≤ h / 2,   |a_jl|, |b_jl| ≤ min(h ω_f l / (4 L), V / (2 L), A / (2 L ω_f l))

    so that Σ_l (|a_jl| + |b_jl|) / (ω_f l) ≤ h / 2 (q within [lo, hi]), Σ_l (|a_jl| + |b_jl|)
    ≤ V and Σ_l (|a_jl| + |b_jl|) ω_f l ≤ A (:meth:`FourierTrajectory.bound` and its
    siblings); the boxes are shrunk by 1e-9 so that rounding cannot reach a bound. The boxes
    split each bound evenly between the harmonics, so after the optimisation each joint's
    a, b are scaled up until the tightest of those sums reaches its bound, kept if that does
    not raise the condition number. Objective:
    log10 of the condition number of the column-normalised base regressor stacked at
    ``samples`` evenly spaced times of one period (default 3 b / n + 10). Start: uniform random
    inside the boxes from ``seed``; minimiser: ``scipy.optimize.minimize(method="L-BFGS-B")``
    with finite-difference gradients, at most ``maxiter`` iterations. Deterministic for a given
    seed.

    Parameters
    ----------
    reg, base:
        The regressor and its base parameters (:func:`eomgen.regressor.base_parameters`).
    period:
        T [s]; ω_f = 2π / T.
    harmonics:
        L, the number of harmonics per joint.
    amplitude:
        Bound on |q_j(t)| [rad or m] when ``bounds`` is None.
    bounds:
        Position ranges and velocity and acceleration bounds (:func:`motion_bounds`).
    """
    from scipy.optimize import minimize

    n, L, b = reg.n, int(harmonics), len(base.base)
    if n == 0:
        raise IdentificationError(f"{reg.model.source}: no movable joint to excite")
    if bounds is None:
        bounds = motion_bounds(reg.model.joint_names, amplitude, source=reg.model.source)
    omega = 2 * math.pi / period
    samples = samples or 3 * b // max(n, 1) + 10
    t = np.arange(samples) * (period / samples)
    f = reg.compiled(values, program=reg.base_program(list(base.base)))
    ws = omega * np.arange(1, L + 1)
    shrink = 1 - 1e-9
    mid = (bounds.lower + bounds.upper) / 2
    half = (bounds.upper - bounds.lower) / 2
    coef = shrink * np.minimum.reduce([
        half[:, None] * ws[None, :] / (4 * L),
        np.broadcast_to(bounds.velocity[:, None] / (2 * L), (n, L)),
        bounds.acceleration[:, None] / (2 * L * ws[None, :])])
    low = np.concatenate([mid - shrink * half / 2, -coef.ravel(), -coef.ravel()])
    high = np.concatenate([mid + shrink * half / 2, coef.ravel(), coef.ravel()])

    def unpack(x):
        x = np.clip(x, low, high)
        return FourierTrajectory(x[:n], x[n:n + n * L].reshape(n, L),
                                 x[n + n * L:].reshape(n, L), omega)

    count = [0]

    def condition(trajectory):
        count[0] += 1
        q, qd, qdd = trajectory.states(t)
        W = np.vstack([f(*row)["Y_base"] for row in zip(q, qd, qdd)])
        c = normalised_condition(W)
        return math.log10(c) if math.isfinite(c) and c < 1e300 else 300.0

    def objective(x):
        return condition(unpack(x))

    def stretched(trajectory):
        # each joint's oscillation scaled up until its tightest bound is reached (by the same
        # sums that bound it): the boxes split each bound evenly between the harmonics, so
        # the optimum usually leaves room
        tr = trajectory
        room = shrink * half - np.abs(tr.q0 - mid)
        with np.errstate(divide="ignore", invalid="ignore"):
            scale = np.nanmin([room / tr._sums(-1), shrink * bounds.velocity / tr._sums(0),
                               shrink * bounds.acceleration / tr._sums(1)], axis=0)
        scale = np.where(np.isfinite(scale), np.maximum(scale, 1.0), 1.0)[:, None]
        return FourierTrajectory(tr.q0, tr.a * scale, tr.b * scale, omega)

    rng = np.random.default_rng(seed)
    x0 = rng.uniform(low, high)
    initial = 10 ** objective(x0)
    result = minimize(objective, x0, method="L-BFGS-B", bounds=list(zip(low, high)),
                      options={"maxiter": int(maxiter)})
    best = unpack(result.x if result.fun <= math.log10(initial) else x0)
    value = condition(best)
    wider = stretched(best)
    wider_value = condition(wider)
    if wider_value <= value:
        best, value = wider, wider_value
    return Excitation(best, initial, 10 ** value, count[0])


def simulate_measurements(model, trajectory: FourierTrajectory, t, noise: float = 0.0,
                          seed: int = 0, values: Mapping | None = None) -> Measurements:
    """Efforts along ``trajectory`` at times ``t`` from eomgen.numeric's recursive
    Newton–Euler (:func:`eomgen.numeric.rnea`), plus Gaussian noise of standard deviation
    ``noise`` times each joint's RMS effort (``noise=0.01``: 1 %), drawn from ``seed``."""
    from ..numeric import numeric_model, rnea

    nm = numeric_model(model, values)
    t = np.asarray(t, dtype=float)
    q, qd, qdd = trajectory.states(t)
    tau = np.array([rnea(nm, *s) for s in zip(q, qd, qdd)]).reshape(len(t), model.dof)
    if noise:
        rms = np.sqrt(np.mean(tau ** 2, axis=0))
        tau = tau + np.random.default_rng(seed).standard_normal(tau.shape) * (noise * rms)
    return Measurements(tuple(model.joint_names), t, q, qd, qdd, tau, False, "<simulated>")
