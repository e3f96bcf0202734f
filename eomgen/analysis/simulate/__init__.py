"""Simulation without torque or damping: integrators against energy drift and trajectory error.

``eomgen simulate`` integrates ``M(q) q̈ + C(q, q̇) q̇ + g(q) = 0`` from a given state with
several integrators and step sizes, and reports, for each run, the wall time against the
energy drift and the trajectory error (against a tight reference solution), sampled on an
output grid. For a chaotic system (the double pendulum) the trajectory error of every method
grows like ``e^{λt}``; past a few seconds it measures the horizon of predictability more than
the method.

* :mod:`~eomgen.analysis.simulate.system`: :class:`System`, the dynamics every integrator calls
  (one derivation printed over Python floats, a plain-Python Cholesky solve), and
  :func:`advance`, the step ``q ⊕ h v`` of a configuration that is not a vector;
* :mod:`~eomgen.analysis.simulate.integrators`: :class:`ExplicitEuler`,
  :class:`SemiImplicitEuler`, :class:`RK4`, :class:`ImplicitMidpoint`, :class:`Adaptive`, and
  their command-line names (:data:`INTEGRATORS`); with quaternion (or planar) joints each steps
  the configuration along the joints' own manifolds (Lie group steps);
* :mod:`~eomgen.analysis.simulate.study`: :func:`simulate` (one run on the output grid) and
  :func:`run_study` (every integrator measured against the reference), :class:`Study`;
* :mod:`~eomgen.analysis.simulate.files`: the Markdown, CSV and PNG files
  (:func:`write_outputs`).

The systems with flexible joints, contacts and loops are beside this package
(:mod:`eomgen.analysis.simulate_flexible`, ``simulate_contacts``, ``simulate_loops``) and use
its integrators and runs.
"""

from __future__ import annotations

from .files import plot, write_outputs
from .integrators import (INTEGRATORS, STIFF, RK4, Adaptive, ExplicitEuler, FixedStep,
                          ImplicitMidpoint, Integrator, SemiImplicitEuler, default_integrators,
                          integrators_named)
from .study import (OUTPUT_POINTS, REFERENCE_TOLERANCE, Run, Study, Trajectory, energies,
                    initial_state, quaternion_start, run_study, simulate)
from .system import Diverged, System, advance

__all__ = ["System", "advance", "ExplicitEuler", "SemiImplicitEuler", "RK4", "ImplicitMidpoint", "Adaptive",
           "Diverged", "Run", "Study", "Trajectory", "simulate", "run_study", "energies",
           "initial_state", "quaternion_start",
           "default_integrators", "integrators_named", "INTEGRATORS", "STIFF", "plot",
           "write_outputs", "FixedStep", "Integrator", "OUTPUT_POINTS", "REFERENCE_TOLERANCE"]
