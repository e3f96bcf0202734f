"""Identification of the base parameters from measured joint efforts (docs/regressor.md).

The pieces, each a plain function over plain data, each in a module of its own and all
importable from here (and from :mod:`eomgen.identification`):

* **Data** (:mod:`~eomgen.identification.measurements`: :func:`read_measurements`,
  :func:`measurements_csv`): a CSV file with a header naming its columns after JOINT_NAMES,
  in any order::

      t, q_<joint>, qd_<joint>, qdd_<joint>, tau_<joint>      (t optional)
      t, q_<joint>, tau_<joint>                               (positions and efforts only)

  SI units (s, rad or m, rad/s or m/s, rad/s² or m/s², N m or N). In the second form q̇ and q̈
  come from :func:`filtered_derivatives`: q and τ through the same zero-phase Butterworth
  low-pass filter (order 4, run forward and backward by ``scipy.signal.sosfiltfilt``), then
  second-order central differences (``numpy.gradient``), then decimation. In the first form
  the columns are used as they are, unless a cut-off is given: then q, q̇, q̈ and τ all go
  through that same filter, trimming and decimation (:func:`filtered_signals`).

  A model with quaternion joints (a free flyer, ball joints) names its ``q_`` columns after
  ``CONFIGURATION_NAMES`` (NQ: ``q_base_x … q_base_qw``, ``q_<ball>_qx … q_<ball>_qw``, then
  the joints) and the others after ``JOINT_NAMES`` (NV: ``qd_base_vx … qd_base_wz`` the root
  twist in the root frame, ``qdd_<ball>_wx``, ``tau_base_vx`` the force on the root along its
  x axis, ...): Pinocchio's q, v, v̇ and τ. Such a file must have the ``qd_`` and ``qdd_``
  columns (a quaternion's rate is not v, so q is not differentiated).
* **Estimation** (:mod:`~eomgen.identification.fit`: :func:`weighted_least_squares`; the
  observation matrix W is :func:`eomgen.regressor.observation_matrix`): Gautier's weighted
  least squares, standard deviations, condition number; :func:`physical_fit` adds the
  constraint that every body's pseudo-inertia be positive semi-definite (an SDP, needs cvxpy).
* **Excitation** (:mod:`~eomgen.identification.excitation`: :class:`FourierTrajectory`,
  :func:`excitation_trajectory`): a finite Fourier series per joint (Swevers et al. 1997)
  whose coefficients minimise the condition number of the base regressor;
  :func:`simulate_measurements` turns it into data with efforts from eomgen.numeric's
  Newton–Euler, plus noise if asked.

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

from ..regressor.least_squares import normalised_condition, observation_matrix
from .excitation import (Excitation, FourierTrajectory, MotionBounds, excitation_trajectory,
                         motion_bounds, simulate_measurements)
from .fit import (Estimate, PhysicalFit, base_map, physical_fit, pseudo_inertia,
                  weighted_least_squares)
from .measurements import (FILTER_ORDER, PREFIXES, Measurements, column_names,
                           filtered_derivatives, filtered_signals, measurements_csv,
                           read_measurements)

__all__ = [
    "PREFIXES", "FILTER_ORDER", "Measurements", "column_names", "measurements_csv",
    "read_measurements", "filtered_derivatives", "filtered_signals",
    "observation_matrix", "normalised_condition",
    "Estimate", "weighted_least_squares", "pseudo_inertia", "base_map", "PhysicalFit",
    "physical_fit",
    "FourierTrajectory", "MotionBounds", "motion_bounds", "Excitation", "excitation_trajectory",
    "simulate_measurements",
]
