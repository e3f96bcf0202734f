"""Numerical analysis of derived dynamics: accuracy, speed and simulation.

=====================  =====================================================================
module                 what
=====================  =====================================================================
``precision``          high-precision (mpmath) reference: the derived program evaluated at
                       40 digits, cross-checked by an mpmath Newton–Euler recursion
``routes``             every way eomgen's dynamics can be evaluated (generated NumPy, CasADi,
                       compiled C, Python scalars, float32, numeric RNEA, Pinocchio)
``bench``              ``eomgen bench``: time per evaluation against the largest error
``simulate``           ``eomgen simulate``: integrators against energy drift and trajectory
                       error
``conditioning``       the Cholesky solve with a condition estimate, and
                       :class:`~eomgen.analysis.conditioning.IllConditionedWarning`
``pinocchio_bridge``   deprecated path of :mod:`eomgen.numeric.pinocchio` (a ``pinocchio.Model``
                       built from a :class:`~eomgen.model.RobotModel`)
``report``             Markdown/CSV tables and the speed-against-error plots
(commands)             ``eomgen bench`` and ``eomgen simulate`` are in :mod:`eomgen.cli.bench_simulate`
=====================  =====================================================================

Nothing here is imported by ``import eomgen``; NumPy is the only hard dependency of
``conditioning`` and ``routes``. ``precision`` needs mpmath (comes with SymPy); ``bench``,
``simulate`` and ``report`` need the ``analysis`` extra (SciPy, Matplotlib). See
``docs/numerics.md``.
"""
