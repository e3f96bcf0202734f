"""Property-based tests (Hypothesis).

* Random valid robots (chains and trees of 1–4 joints: revolute, continuous, prismatic and fixed
  joints with random axes and origins; random masses, centres of mass and inertias satisfying
  the triangle inequality), given as a model, a URDF or an eomgen YAML file, load and pass
  :func:`eomgen.verify`.
* Random corruptions of valid description *text* (spans deleted, lines duplicated or swapped,
  numbers replaced by ``nan``, ``-1``, ``abc``..., tag or key names swapped, stray characters
  inserted, bytes that are not UTF-8, truncation) end in an :class:`~eomgen.errors.EomgenError`
  with a one-line message, or in a valid model; never in any other exception.

Examples are derandomized (the same on every run, so the suite never flakes) and the example
database is off (nothing written into the checkout). To explore further, run with
``EOMGEN_HYPOTHESIS_EXAMPLES=2000`` (random examples, that many per corruption test).
"""

from __future__ import annotations

import math
import os
import re
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import eomgen
from eomgen.errors import EomgenError
from eomgen.model import (Inertial, Joint, JointType, Link, RobotModel, Transform, build_model,
                          rotation_from_rpy, vec3)

EXPLORE = int(os.environ.get("EOMGEN_HYPOTHESIS_EXAMPLES", "0"))
COMMON = dict(deadline=None, database=None, derandomize=not EXPLORE,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                     HealthCheck.filter_too_much])


def finite(low: float, high: float):
    return st.floats(low, high, allow_nan=False, allow_infinity=False)


# ----------------------------------------------------------------------------------------------
# Random valid robots: a plain specification, written as a model, URDF or YAML
# ----------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class BodySpec:
    mass: float
    com: tuple[float, float, float]
    inertia: tuple[tuple[float, float, float], ...]  # symmetric, about the COM, link axes


@dataclass(frozen=True)
class JointSpec:
    kind: str
    parent: int  # 0 is the base, k is link k
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    axis: tuple[float, float, float]


@dataclass(frozen=True)
class RobotSpec:
    bodies: tuple[BodySpec, ...]   # link k + 1
    joints: tuple[JointSpec, ...]  # joint k + 1, child link k + 1


angles = finite(-math.pi, math.pi)
vectors = st.tuples(finite(-0.5, 0.5), finite(-0.5, 0.5), finite(-0.5, 0.5))


@st.composite
def bodies(draw) -> BodySpec:
    """Principal moments a, b, c with |a − b| ≤ c ≤ a + b, turned by a random rotation."""
    a, b = draw(finite(0.01, 1.0)), draw(finite(0.01, 1.0))
    c = draw(finite(max(abs(a - b), 0.01), a + b))
    R = np.array(rotation_from_rpy(vec3(draw(st.tuples(angles, angles, angles)))), dtype=float)
    full = R @ np.diag([a, b, c]) @ R.T
    upper = {(i, j): float(full[i, j]) for i in range(3) for j in range(i, 3)}
    inertia = tuple(tuple(upper[min(i, j), max(i, j)] for j in range(3)) for i in range(3))
    com = draw(st.tuples(finite(-0.3, 0.3), finite(-0.3, 0.3), finite(-0.3, 0.3)))
    return BodySpec(draw(finite(0.1, 5.0)), com, inertia)


axes = st.one_of(
    st.sampled_from([(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (0.0, 0.0, -1.0)]),
    st.tuples(finite(-1, 1), finite(-1, 1), finite(-1, 1)).filter(
        lambda v: math.sqrt(sum(x * x for x in v)) > 0.2))


@st.composite
def robots(draw, max_joints: int = 4) -> RobotSpec:
    n = draw(st.integers(1, max_joints))
    joints = []
    for k in range(n):
        kind = draw(st.sampled_from(["revolute", "continuous", "prismatic", "fixed"]))
        joints.append(JointSpec(kind, draw(st.integers(0, k)), draw(vectors),
                                draw(st.tuples(angles, angles, angles)), draw(axes)))
    if all(j.kind == "fixed" for j in joints):
        joints[0] = JointSpec("revolute", *[getattr(joints[0], f) for f in
                                            ("parent", "xyz", "rpy", "axis")])
    return RobotSpec(tuple(draw(bodies()) for _ in range(n)), tuple(joints))


def link_name(k: int) -> str:
    return "base" if k == 0 else f"link{k}"


def to_model(spec: RobotSpec) -> RobotModel:
    links = [Link("base")] + [Link(link_name(k + 1), Inertial(b.mass, b.com, b.inertia))
                              for k, b in enumerate(spec.bodies)]
    joints = [Joint(f"joint{k + 1}", JointType(j.kind), link_name(j.parent), link_name(k + 1),
                    Transform.from_xyz_rpy(j.xyz, j.rpy), vec3(j.axis))
              for k, j in enumerate(spec.joints)]
    return build_model("<hypothesis>", "random_robot", links, joints)


def _numbers(values) -> str:
    return " ".join(repr(float(v)) for v in values)


def to_urdf(spec: RobotSpec) -> str:
    out = ['<?xml version="1.0"?>', '<robot name="random_robot">', '  <link name="base"/>']
    for k, b in enumerate(spec.bodies):
        (xx, xy, xz), (_, yy, yz), (_, _, zz) = b.inertia
        out += [f'  <link name="{link_name(k + 1)}">', "    <inertial>",
                f'      <origin xyz="{_numbers(b.com)}"/>', f'      <mass value="{b.mass!r}"/>',
                f'      <inertia ixx="{xx!r}" ixy="{xy!r}" ixz="{xz!r}" iyy="{yy!r}" '
                f'iyz="{yz!r}" izz="{zz!r}"/>', "    </inertial>", "  </link>"]
    for k, j in enumerate(spec.joints):
        out += [f'  <joint name="joint{k + 1}" type="{j.kind}">',
                f'    <parent link="{link_name(j.parent)}"/>',
                f'    <child link="{link_name(k + 1)}"/>',
                f'    <origin xyz="{_numbers(j.xyz)}" rpy="{_numbers(j.rpy)}"/>',
                f'    <axis xyz="{_numbers(j.axis)}"/>', "  </joint>"]
    return "\n".join(out + ["</robot>", ""])


def _list(values) -> str:
    return "[" + ", ".join(repr(float(v)) for v in values) + "]"


def to_yaml(spec: RobotSpec) -> str:
    out = ["name: random_robot", "links:", "  - name: base"]
    for k, b in enumerate(spec.bodies):
        (xx, xy, xz), (_, yy, yz), (_, _, zz) = b.inertia
        out += [f"  - name: {link_name(k + 1)}", f"    mass: {b.mass!r}",
                f"    com: {_list(b.com)}",
                f"    inertia: {{ixx: {xx!r}, iyy: {yy!r}, izz: {zz!r}, ixy: {xy!r}, "
                f"ixz: {xz!r}, iyz: {yz!r}}}"]
    out.append("joints:")
    for k, j in enumerate(spec.joints):
        out += [f"  - name: joint{k + 1}", f"    type: {j.kind}",
                f"    parent: {link_name(j.parent)}", f"    child: {link_name(k + 1)}",
                f"    origin: {{xyz: {_list(j.xyz)}, rpy: {_list(j.rpy)}}}",
                f"    axis: {_list(j.axis)}"]
    return "\n".join(out) + "\n"


WRITERS = {".urdf": to_urdf, ".yaml": to_yaml}


def load_text(text: str | bytes, suffix: str) -> RobotModel:
    """``eomgen.load`` of ``text`` written to a file (the real entry point: size checks, format
    sniffing, decoding)."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder, "robot" + suffix)
        path.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8"))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return eomgen.load(path)


@settings(max_examples=12, **COMMON)
@given(spec=robots(), form=st.sampled_from(["model", ".urdf", ".yaml"]))
@pytest.mark.slow
def test_random_valid_robots_pass_verification(spec, form):
    model = to_model(spec) if form == "model" else load_text(WRITERS[form](spec), form)
    assert model.dof == sum(j.kind != "fixed" for j in spec.joints)
    dynamics = eomgen.derive(model)
    report = eomgen.verify(dynamics, samples=3, seed=1)
    assert report.passed, f"{form}\n{report.format()}\n{WRITERS['.urdf'](spec)}"


def test_text_forms_describe_the_same_robot():
    """The URDF and YAML writers above are faithful: all three forms give the same dynamics
    (so the verification property covers the parsers too)."""
    spec = _FIXED_SPEC
    models = [to_model(spec), load_text(to_urdf(spec), ".urdf"), load_text(to_yaml(spec), ".yaml")]
    states = np.random.default_rng(2).uniform(-2, 2, size=(3, models[0].dof))
    from eomgen.numeric import numeric_model, rnea

    for q in states:
        taus = [rnea(numeric_model(m), q, q / 2, q / 3) for m in models]
        for tau in taus[1:]:
            np.testing.assert_allclose(tau, taus[0], rtol=1e-12, atol=1e-12)


_FIXED_SPEC = RobotSpec(
    bodies=(BodySpec(1.2, (0.1, 0.0, -0.05), ((0.02, 0.001, 0.0), (0.001, 0.03, 0.002),
                                                (0.0, 0.002, 0.04))),
            BodySpec(0.7, (0.0, 0.2, 0.0), ((0.01, 0.0, 0.0), (0.0, 0.01, 0.0), (0.0, 0.0, 0.015))),
            BodySpec(0.3, (0.05, 0.05, 0.05), ((0.005, 0.0, 0.0), (0.0, 0.006, 0.0),
                                               (0.0, 0.0, 0.007)))),
    joints=(JointSpec("revolute", 0, (0.0, 0.0, 0.3), (0.1, -0.2, 0.3), (0.0, 0.0, 1.0)),
            JointSpec("prismatic", 1, (0.2, 0.0, 0.0), (0.0, 0.5, 0.0), (0.6, 0.8, 0.0)),
            JointSpec("continuous", 1, (0.0, 0.1, 0.0), (1.0, 0.0, -1.0), (1.0, 0.0, 0.0))))


# ----------------------------------------------------------------------------------------------
# Corruptions of valid text: a clean EomgenError or a valid model, nothing else
# ----------------------------------------------------------------------------------------------

SEEDS = [(".yaml", eomgen.example_path("planar_2link").read_text(encoding="utf-8")),
         (".yaml", eomgen.example_path("puma560_dh").read_text(encoding="utf-8")),
         (".urdf", to_urdf(_FIXED_SPEC)), (".yaml", to_yaml(_FIXED_SPEC))]

NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?")
TAG = re.compile(r"(?<=<)/?([A-Za-z_]+)")
KEY = re.compile(r"^(\s*-?\s*)([A-Za-z_]+)(?=:)", re.MULTILINE)
REPLACEMENTS = ["nan", "-1", "abc", "1e400", "-inf", "0", "1e308", "9" * 5000, "", "1/0", "()",
                "[1, 2]", "{a: 1}", "*x", "&x", "!!python/name:os.system", "0x10", "1_0",
                "sqrt(-1)", "10**400", "'", '"', "<", "&amp;", "&lol;", "\u2028", "1e-320",
                "-0.0", "q1", "lambda", "pi/0"]
STRAY = st.text(st.sampled_from(list("<>&\"'\n\t :[]{}-#*!%@`\\/=,.;?|0123456789eé\u2028")),
                min_size=1, max_size=6)


@st.composite
def corruptions(draw, text: str) -> str | bytes:
    """``text`` with one to three random corruptions (see the module docstring)."""
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["delete", "duplicate line", "swap lines", "number",
                                     "swap names", "insert", "truncate"]))
        if kind == "delete" and text:
            start = draw(st.integers(0, len(text) - 1))
            text = text[:start] + text[start + draw(st.integers(1, 40)):]
        elif kind in ("duplicate line", "swap lines"):
            lines = text.split("\n")
            i = draw(st.integers(0, len(lines) - 1))
            if kind == "duplicate line":
                lines.insert(i, lines[i])
            else:
                j = draw(st.integers(0, len(lines) - 1))
                lines[i], lines[j] = lines[j], lines[i]
            text = "\n".join(lines)
        elif kind == "number":
            found = list(NUMBER.finditer(text))
            if found:
                m = found[draw(st.integers(0, len(found) - 1))]
                text = text[:m.start()] + draw(st.sampled_from(REPLACEMENTS)) + text[m.end():]
        elif kind == "swap names":
            found = list(TAG.finditer(text)) or list(KEY.finditer(text))
            if len(found) >= 2:
                group = 1 if found[0].re is TAG else 2
                a, b = sorted(draw(st.lists(st.integers(0, len(found) - 1), min_size=2,
                                            max_size=2, unique=True)))
                ma, mb = found[a], found[b]
                text = (text[:ma.start(group)] + mb.group(group) + text[ma.end(group):mb.start(group)]
                        + ma.group(group) + text[mb.end(group):])
        elif kind == "insert":
            at = draw(st.integers(0, len(text)))
            text = text[:at] + draw(STRAY) + text[at:]
        elif kind == "truncate":
            text = text[:draw(st.integers(0, len(text)))]
    if draw(st.integers(0, 19)) == 0:  # now and then, bytes that are not UTF-8
        data = text.encode("utf-8")
        at = draw(st.integers(0, len(data)))
        return data[:at] + b"\xff\xfe" + data[at:]
    return text


def check_clean(text: str | bytes, suffix: str) -> None:
    """Loading ends in an EomgenError with a one-line message, or in a model that derives."""
    try:
        model = load_text(text, suffix)
        if model.dof <= 3:
            eomgen.derive(model)
    except EomgenError as exc:
        message = str(exc)
        assert message and "\n" not in message and "\r" not in message, message
    except Exception as exc:  # noqa: BLE001 - the property under test
        shown = text if isinstance(text, str) else text.decode("utf-8", "replace")
        pytest.fail(f"{type(exc).__name__}: {exc}\n--- input ({suffix}) ---\n{shown}")
    else:
        assert isinstance(model, RobotModel)


@settings(max_examples=EXPLORE or 150, **COMMON)
@given(data=st.data(), seed=st.sampled_from(SEEDS))
@pytest.mark.slow
def test_corrupted_bundled_and_fixed_descriptions_fail_cleanly(data, seed):
    suffix, text = seed
    check_clean(data.draw(corruptions(text), label="corrupted"), suffix)


@settings(max_examples=EXPLORE or 100, **COMMON)
@given(data=st.data(), spec=robots(max_joints=3), suffix=st.sampled_from([".urdf", ".yaml"]))
def test_corrupted_random_descriptions_fail_cleanly(data, spec, suffix):
    check_clean(data.draw(corruptions(WRITERS[suffix](spec)), label="corrupted"), suffix)
