"""Short reprs of the big objects a user meets (a model, derived dynamics, a scene's report),
and the parts' reprs with each number as the shortest text that reads back to its double."""

from __future__ import annotations

import functools
import re

import sympy as sp

import eomgen
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene


@functools.cache
def planar():
    return eomgen.derive(eomgen.load(eomgen.example_path("planar_2link")))


def test_a_model_is_one_line_naming_its_sizes_joints_and_parameters():
    model = eomgen.load(eomgen.example_path("puma560_dh"))
    text = repr(model)
    assert text == (f"<RobotModel 'puma560': nq=6, nv=6, joints joint1, joint2, joint3, joint4, "
                    f"joint5, joint6; 7 links; no parameters; from {model.source}>")
    assert len(model.links) == 7 and model.nq == model.dof == 6 and not model.parameters


def test_dynamics_are_one_line_naming_the_outputs_and_parameters():
    dyn = planar()
    text = repr(dyn)
    assert "\n" not in text and len(text) < 200
    assert text.startswith("<Dynamics of 'planar_2link': nq=2, nv=2; outputs ")
    assert "outputs " + ", ".join(dyn.outputs) + ";" in text
    count = len(dyn.model.parameters)
    assert f"; {count} parameters ({dyn.model.parameters[0].name}, " in text and count > 6
    assert f"(… {count - 6} more)" not in text and f"… ({count - 6} more)" in text


def test_a_scene_report_is_one_line():
    model = eomgen.load(eomgen.example_path("planar_2link"))
    report = apply_scene(model, load_scene("lock.yaml", text="version: 1\nlocked: {joint2: 0}\n"
                                                             "outputs: [M, g]\n")).report
    text = repr(report)
    assert text == (f"<ReductionReport of 'planar_2link' by scene 'lock.yaml': "
                    f"{report.moving_summary()} (joint1); outputs "
                    f"{', '.join(report.outputs)}; {len(report.notes)} notes>")
    assert report.moving == ("joint1",)


def _numbers(text: str) -> list[str]:
    return re.findall(r"(?<![\w.])-?\d+\.\d+(?:e-?\d+)?", text)


def test_parts_print_each_number_as_the_shortest_text_of_its_double():
    """URDF's 0.629769 is kept as a 17-digit SymPy Float (its str: 0.62976900000000002); the
    reprs print what reads back to the same double."""
    model = eomgen.load(eomgen.example_path("puma560_dh"))
    link = model.link_by_name["link2"]
    text = repr(link)
    assert "mass=17.4," in text and "0.2275" in text
    floats = [x for x in sp.preorder_traversal(link.inertial.com) if isinstance(x, sp.Float)]
    assert floats and all(str(x) != repr(float(x)) for x in floats)  # the noise, at the root
    for number in _numbers(text) + _numbers(repr(model.joints[2])):
        assert repr(float(number)) == number  # the shortest round trip
    inertial = eomgen.model.Inertial(sp.Float(0.629769, 17) * sp.Symbol("s"), (0.5, 0, 0))
    assert repr(inertial).startswith("Inertial(mass=0.629769*s, com=(0.5, 0, 0), ")
