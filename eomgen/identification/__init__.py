"""Identification of the base parameters from measured joint efforts (docs/regressor.md).

The functions live in :mod:`eomgen.identification.estimation` (data, weighted least squares,
physically consistent fit, excitation trajectories) and :mod:`eomgen.identification.report`;
they are importable from here too. Loaded on first use: importing the command line
(:mod:`eomgen.cli.excite_identify`) must not import NumPy, so that a cached
``eomgen generate`` stays light.
"""

from __future__ import annotations

from ..errors import IdentificationError  # noqa: F401  (re-exported)


def __getattr__(name: str):
    # imported on first use (start-up time): the command line imports this package and must
    # not load NumPy for a cached ``eomgen generate``
    import eomgen.identification.estimation as estimation  # not "from . import": that asks
    # this __getattr__ for the submodule before importing it

    try:
        return getattr(estimation, name)
    except AttributeError:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
