"""Controllers over generated dynamics, as a control designer uses them (docs/control.md):
computed torque, PD plus gravity compensation and the adaptive controller of Slotine and Li on
the Slotine–Li regressor (:mod:`~eomgen.control.laws`), and their closed loops simulated
(:mod:`~eomgen.control.closed_loop`)."""

from __future__ import annotations

from .closed_loop import ClosedLoop, simulate
from .laws import (ComputedTorque, Desired, PDGravity, SlotineLi, estimated_mass_matrix,
                   fourier_reference)

__all__ = ["ClosedLoop", "simulate", "ComputedTorque", "Desired", "PDGravity", "SlotineLi",
           "estimated_mass_matrix", "fourier_reference"]
