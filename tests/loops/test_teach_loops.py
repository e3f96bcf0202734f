"""The four-bar in ``eomgen teach``: a section on the loop closure whose written-out constraint
Φ(q), Jacobian and joint torques with the multipliers λ are those of the four-bar by hand
(Φ = tip of the coupler − tip of the rocker, J_l = ∂Φ/∂q)."""

from __future__ import annotations

import numpy as np
import sympy as sp

import eomgen
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import ROOT


def test_fourbar_handout_writes_the_loop_out():
    from eomgen.teach.content import build_handout
    from eomgen.teach.loops import loop_equations

    reduction = apply_scene(eomgen.load(ROOT / "examples/robots/fourbar.yaml"),
                            load_scene(ROOT / "examples/loops/fourbar_loop.yaml"))
    handout = build_handout(reduction.model, check=False, scene=reduction.report)
    titles = [s.title for s in handout.sections]
    assert "Loop closures" in titles and titles.index("Loop closures") < len(titles) - 1
    dyn = eomgen.derive(reduction.model, outputs=("M", "C", "g"), simplify=False)
    Phi, J, _, lam, equations = loop_equations(dyn, None, None)
    q1, q2, q3 = dyn.q
    a, d = (next(p.symbol for p in reduction.model.parameters if p.name == n) for n in "ad")
    by_hand = sp.Matrix([a * sp.cos(q1) + 0.6 * sp.cos(q1 + q2) - d - 0.5 * sp.cos(q3),
                         a * sp.sin(q1) + 0.6 * sp.sin(q1 + q2) - 0.5 * sp.sin(q3)])
    rng = np.random.default_rng(1)
    for _ in range(3):
        at = dict(zip((q1, q2, q3, a, d), rng.uniform(-3, 3, 5)))
        assert np.allclose(np.array(Phi.subs(at), dtype=float),
                           np.array(by_hand.subs(at), dtype=float), atol=1e-12)
        assert np.allclose(np.array(J.subs(at), dtype=float),
                           np.array(by_hand.jacobian([q1, q2, q3]).subs(at), dtype=float),
                           atol=1e-12)
    # τ_3 (the rocker) carries −(J_lᵀ λ)_3 = −(0.5 s3 λ1 − 0.5 c3 λ2)
    tau3 = sp.Add(*equations[2][1])
    assert sp.simplify(tau3.coeff(lam[0]) + 0.5 * sp.sin(q3)) == 0
