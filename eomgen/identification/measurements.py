"""Measured data for identification: the CSV format (:func:`read_measurements`,
:func:`measurements_csv`) and the zero-phase filtering that gives q̇ and q̈ from q
(:func:`filtered_derivatives`, :func:`filtered_signals`). See
:mod:`eomgen.identification.estimation` for the format."""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from ..common.reading import not_regular
from ..errors import IdentificationError, one_line

#: Column prefixes of a CSV file, in the order written: positions, velocities, accelerations,
#: efforts, each followed by ``_<joint name>``.
PREFIXES = ("q", "qd", "qdd", "tau")


#: Order of the Butterworth low-pass filter of :func:`filtered_derivatives` (run forward and
#: backward, so the effective order is twice this and the phase is zero).
FILTER_ORDER = 4


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
    configuration_names : tuple of str, (nq,), or None
        The names of ``q``'s columns when they are not ``joint_names``: a model with
        quaternion joints (``CONFIGURATION_NAMES``, NQ entries; q̇, q̈, τ keep the NV
        ``joint_names``).
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
    configuration_names: tuple[str, ...] | None = None

    @property
    def N(self) -> int:
        """Number of samples."""
        return self.q.shape[0]

    @property
    def position_names(self) -> tuple[str, ...]:
        """The names of ``q``'s columns: :attr:`configuration_names`, else the joints'."""
        return self.joint_names if self.configuration_names is None else self.configuration_names


def column_names(joint_names: Sequence[str], derivatives: bool = True, time: bool = True,
                 configuration_names: Sequence[str] | None = None) -> list[str]:
    """The CSV header: ``t`` (if ``time``), then ``q_<joint>`` for every joint, ``qd_``,
    ``qdd_`` (if ``derivatives``) and ``tau_``. With ``configuration_names`` (a model with
    quaternion joints: ``CONFIGURATION_NAMES``) the ``q_`` columns are named after those
    (``q_base_x … q_base_qw``, ``q_hip_qx … q_hip_qw``), the others after the NV joints
    (``qd_base_vx``, ``qdd_hip_wz``, ``tau_base_wx``: v, v̇ and the effort along each
    velocity coordinate)."""
    positions = joint_names if configuration_names is None else configuration_names
    names = ["t"] if time else []
    for prefix in (PREFIXES if derivatives else ("q", "tau")):
        names += [f"{prefix}_{j}" for j in (positions if prefix == "q" else joint_names)]
    return names


def measurements_csv(m: Measurements, derivatives: bool = True) -> str:
    """The CSV text of ``m`` (header :func:`column_names`; shortest round-trip float text, so
    reading it back gives the same numbers). ``derivatives=False`` leaves out q̇ and q̈."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(column_names(m.joint_names, derivatives, m.t is not None,
                                 m.configuration_names))
    blocks = [m.q, m.qd, m.qdd, m.tau] if derivatives else [m.q, m.tau]
    data = np.hstack(([m.t[:, None]] if m.t is not None else []) + blocks)
    for row in data:
        writer.writerow([repr(float(x)) for x in row])
    return out.getvalue()


def read_measurements(path: Path | str, joint_names: Sequence[str],
                      cutoff: float | None = None,
                      configuration_names: Sequence[str] | None = None,
                      quaternions: Sequence[int] = ()) -> Measurements:
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
    configuration_names:
        ``CONFIGURATION_NAMES`` of a model with quaternion joints: its ``q_`` columns (NQ);
        None: ``joint_names``.
    quaternions:
        The index in ``q`` of each quaternion's x (then y, z, w). Such a model's file must
        have the ``qd_`` and ``qdd_`` columns (v and v̇: a quaternion's rate is not v, so q
        is not differentiated); before a cut-off filters q, each quaternion's sign is made
        continuous (q and −q are one rotation), so the filter smooths a continuous signal.

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
    problem = not_regular(path)
    if problem is not None:
        raise IdentificationError(f"{source}: {problem}")
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
    if differentiate and quaternions:
        raise IdentificationError(one_line(
            f"{source}: line 1: no qd_, qdd_ columns: a model with quaternion joints needs "
            "them (v and its rate, JOINT_NAMES), as a quaternion's rate is not v"))
    positions = tuple(joint_names if configuration_names is None else configuration_names)
    expected = column_names(joint_names, derivatives=not differentiate, time=True,
                            configuration_names=positions)
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
        names = positions if prefix == "q" else joint_names
        return np.column_stack([column[f"{prefix}_{j}"] for j in names]) if names \
            else np.zeros((data.shape[0], 0))

    t = column.get("t")
    q, tau = block("q"), block("tau")
    named = positions if configuration_names is not None else None
    if not differentiate:
        if cutoff is None:
            return Measurements(tuple(joint_names), t, q, block("qd"), block("qdd"), tau, False,
                                source, configuration_names=named)
        if t is None:
            raise IdentificationError(f"{source}: line 1: missing column 't' (needed to filter "
                                      f"at the cut-off {cutoff:.6g} Hz)")
        q = continuous_quaternions(q, quaternions)
        t, (q, qd, qdd, tau), used = filtered_signals(t, (q, block("qd"), block("qdd"), tau),
                                                      cutoff, source)
        return Measurements(tuple(joint_names), t, q, qd, qdd, tau, False, source, used,
                            configuration_names=named)
    t, q, qd, qdd, tau, used = _filtered_derivatives(t, q, tau, cutoff, source)
    return Measurements(tuple(joint_names), t, q, qd, qdd, tau, True, source, used)


def continuous_quaternions(q, quaternions: Sequence[int]) -> np.ndarray:
    """``q`` (N, NQ) with the sign of each quaternion (columns ``k … k + 3`` for ``k`` in
    ``quaternions``) flipped where it would jump: sample i + 1 takes the sign whose dot product
    with sample i is not negative (``q`` and ``−q`` are one rotation)."""
    q = np.array(q, dtype=float)
    for k in quaternions:
        block = q[:, k:k + 4]
        for i in range(1, len(block)):
            if block[i] @ block[i - 1] < 0:
                block[i] = -block[i]
    return q


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
    from scipy import signal  # an optional dependency (eomgen[identify])

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
