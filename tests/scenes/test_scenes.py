"""Scenes (:mod:`eomgen.scene`) and model reduction (:mod:`eomgen.reduction`).

The reduced model's M, C, g and τ must equal the whole robot's with the same joints locked and
the same payloads carried. The independent reference is Pinocchio: ``pin.buildReducedModel`` on
the robot read by Pinocchio's own URDF reader (example-robot-data) or built joint by joint from
ours (random trees, ``reference.to_pinocchio``), with payloads added to the inertia of the joint
their link is attached to. Comparisons are relative, at random states, through the compiled
straight-line program: ``max|a − b| ≤ RTOL · max(1, max|b|)``.

Further: bad scenes (one line naming the scene file and the entry, exit code 2, nothing
written), what the report counts, structural zeros, planar motion, and that only the asked
outputs are derived and generated.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib.util
import warnings

import numpy as np
import pytest
from click.testing import CliRunner

import eomgen
from eomgen.cli import main
from eomgen.dynamics import derive
from eomgen.errors import DescriptionError, SceneError
from eomgen.model import Inertial, Joint, JointType, Link, RobotModel, Transform
from eomgen.reduction import Reduction, apply_scene, planar_motion
from eomgen.scene import PLANNED_KEYS, SCENE_KEYS, Scene, load_scene
from eomgen.symbolic.evaluate import compile_program
from support import ROOT, assert_close, erd_robots_dir, run_process
from support.reference import random_robot, to_pinocchio
from support.extras import need

SCENES = ROOT / "examples" / "scenes"
RTOL = 1e-10
ALL = ("M", "C", "g", "tau")

#: Example scenes and the example-robot-data file each applies to.
EXAMPLES = {
    "panda_fingers_locked": "panda_description/urdf/panda.urdf",
    "ur5_payload": "ur_description/urdf/ur5_robot.urdf",
    "talos_left_arm": "talos_data/robots/talos_reduced.urdf",
    "panda_two_joints": "panda_description/urdf/panda.urdf",
    "panda_flexible": "panda_description/urdf/panda.urdf",  # docs/actuators.md
}




@functools.cache
def erd_model(relative: str) -> RobotModel:
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the Panda's mimic finger read as independent
        return eomgen.load(robots / relative, couplings=False)  # as Pinocchio's default


def scene_text(text: str, name: str = "scene.yaml") -> Scene:
    return load_scene(name, text=text)


# ----------------------------------------------------------------------------------------------
# The reference: Pinocchio with the same joints locked and payloads carried
# ----------------------------------------------------------------------------------------------


def pin_reference(pmodel, model: RobotModel, reduction: Reduction, scene: Scene):
    """Pinocchio's reduction of ``pmodel`` (the whole ``model``) as ``reduction`` locked it,
    with ``scene``'s payloads (at parameter defaults) added first."""
    import pinocchio as pin

    pmodel = pin.Model(pmodel)
    values = {p.symbol: p.value for p in list(model.parameters) + list(scene.parameters)}
    for payload in scene.payloads:
        if payload.link == model.root:  # the world: to_pinocchio names no frame after it
            continue
        frame = pmodel.frames[pmodel.getFrameId(payload.link)]
        inertial = payload.inertial
        as_float = lambda x: float(x.xreplace(values))  # noqa: E731
        Y = pin.Inertia(as_float(inertial.mass), np.array([as_float(c) for c in inertial.com]),
                        np.array([[as_float(v) for v in row] for row in inertial.inertia]))
        pmodel.inertias[frame.parentJoint] = (pmodel.inertias[frame.parentJoint]
                                              + frame.placement.act(Y))
    q_ref = pin.neutral(pmodel)
    ids = []
    for locked in reduction.report.locked:
        jid = pmodel.getJointId(locked.name)
        ids.append(jid)
        q_ref[pmodel.joints[jid].idx_q] = locked.position
    reduced = pin.buildReducedModel(pmodel, ids, q_ref) if ids else pmodel
    reduced.gravity = pin.Motion(np.array([float(g) for g in _gravity(model, scene)]),
                                 np.zeros(3))
    return reduced


def _gravity(model: RobotModel, scene: Scene):
    return model.gravity if scene.gravity is None else scene.gravity


class Compared:
    """Our reduced dynamics against Pinocchio's reduced model at random states."""

    def __init__(self, reduction: Reduction, pmodel, outputs=ALL):
        self.model = reduction.model
        self.dyn = derive(self.model, outputs=outputs, simplify=False)
        params = [p.symbol for p in self.model.parameters]
        self.values = [self.model.parameter_values[s] for s in params]
        self.f = compile_program(self.dyn.program,
                                 list(self.dyn.q) + list(self.dyn.qd) + list(self.dyn.qdd) + params)
        self.pmodel = pmodel
        self.data = pmodel.createData()
        names = list(self.model.joint_names)
        assert sorted(pmodel.names[1:]) == sorted(names), (pmodel.names[1:], names)
        self.perm = np.empty(pmodel.nv, dtype=int)  # x_pin = x[perm]
        for jid in range(1, pmodel.njoints):
            assert pmodel.joints[jid].nq == 1
            self.perm[pmodel.joints[jid].idx_q] = names.index(pmodel.names[jid])
        self.inv = np.argsort(self.perm)

    def check(self, seed: int, states: int = 3) -> None:
        import pinocchio as pin

        rng = np.random.default_rng(seed)
        n, pm, data, inv = self.model.dof, self.pmodel, self.data, self.inv
        for _ in range(states):
            q, qd, qdd = rng.uniform(-np.pi, np.pi, n), rng.normal(size=n), rng.normal(size=n)
            ours = self.f(*q, *qd, *qdd, *self.values)
            x, v, a = q[self.perm], qd[self.perm], qdd[self.perm]
            M = np.array(pin.crba(pm, data, x))
            M = np.triu(M) + np.triu(M, 1).T
            theirs = {
                "M": M[np.ix_(inv, inv)],
                "C": np.array(pin.computeCoriolisMatrix(pm, data, x, v))[np.ix_(inv, inv)],
                "g": np.array(pin.computeGeneralizedGravity(pm, data, x))[inv],
                "tau": np.array(pin.rnea(pm, data, x, v, a))[inv],
            }
            for name in self.dyn.outputs:
                if name in theirs:
                    got = ours[name][:, 0] if name in ("g", "tau") else ours[name]
                    assert_close(got, theirs[name], f"{self.model.name} {name} at q={q}")


def compare_example(name: str, seed: int) -> Reduction:
    pin = need("pinocchio")
    model = erd_model(EXAMPLES[name])
    scene = load_scene(SCENES / f"{name}.yaml")
    reduction = apply_scene(model, scene)
    pmodel = pin.buildModelFromUrdf(str(erd_robots_dir() / EXAMPLES[name]))
    Compared(reduction, pin_reference(pmodel, model, reduction, scene)).check(seed)
    return reduction


# ----------------------------------------------------------------------------------------------
# Example-robot-data robots
# ----------------------------------------------------------------------------------------------


def test_panda_with_fingers_locked_equals_pinocchio_reduced_model():
    reduction = compare_example("panda_fingers_locked", seed=1)
    report = reduction.report
    assert reduction.model.joint_names == tuple(f"panda_joint{k}" for k in range(1, 8))
    assert {(j.name, j.position, j.listed) for j in report.locked} == {
        ("panda_finger_joint1", 0.02, True), ("panda_finger_joint2", 0.02, True)}
    hand = {b.link: b for b in report.merged}["panda_link7"]
    assert {"panda_link8", "panda_hand", "panda_leftfinger", "panda_rightfinger"} <= set(hand.links)
    assert (report.before.dof, report.after.dof) == (9, 7)


def test_panda_shoulder_and_elbow_teaching_scene_equals_pinocchio_reduced_model():
    """The scene eomgen teach uses to make a two-link arm of the Panda: planar, two joints."""
    reduction = compare_example("panda_two_joints", seed=4)
    assert reduction.model.joint_names == ("panda_joint2", "panda_joint4")
    assert reduction.report.planar is not None and reduction.report.planar.gravity == "in the plane"
    assert (reduction.report.before.dof, reduction.report.after.dof) == (9, 2)


def test_one_arm_of_talos_equals_pinocchio_with_every_other_joint_locked():
    reduction = compare_example("talos_left_arm", seed=2)
    report = reduction.report
    assert reduction.model.joint_names == tuple(f"arm_left_{k}_joint" for k in range(1, 8))
    assert len(report.locked) == 32 - 7
    assert set(report.locked_by_default) == {j.name for j in report.locked} - {
        "torso_2_joint", "gripper_left_joint"}
    assert "leg_left_6_link" in report.dropped and "torso_2_link" in report.dropped
    assert report.after.links == 8 and report.after.joints == 7
    assert "`torso_1_joint`" in report.markdown()  # locked at 0: said so


def test_ur5_with_a_payload_equals_pinocchio_with_the_payload_inertia_added():
    reduction = compare_example("ur5_payload", seed=3)
    assert [p.name for p in reduction.model.parameters] == ["m_load"]
    merged = {b.link: b for b in reduction.report.merged}["wrist_3_link"]
    assert merged.payloads == ("gripper_and_part",) and "tool0" in merged.links


def test_ur5_payload_mass_stays_a_parameter_that_changes_the_dynamics():
    model = erd_model(EXAMPLES["ur5_payload"])
    reduced, _ = apply_scene(model, load_scene(SCENES / "ur5_payload.yaml"))
    dyn = derive(reduced, outputs=("g",))
    m_load = reduced.parameters[0].symbol
    f = compile_program(dyn.program, list(dyn.q) + [m_load])
    q = np.array([0.3, -1.0, 1.2, 0.4, 0.8, -0.2])
    empty = derive(apply_scene(model).model, outputs=("g",))
    g0 = compile_program(empty.program, list(empty.q))(*q)["g"]
    assert_close(f(*q, 0.0)["g"], g0, "payload of mass 0")
    assert not np.allclose(f(*q, 2.0)["g"], g0)


#: Example scenes for the bundled robots (eomgen.example_path) and the robot each applies to.
BUNDLED_EXAMPLES = {"planar_2link_mixed_drives": "planar_2link"}  # docs/actuators.md


def test_every_example_scene_loads_and_names_its_robot():
    assert sorted(p.stem for p in SCENES.glob("*.yaml")) == sorted({**EXAMPLES,
                                                                     **BUNDLED_EXAMPLES})
    for name, relative in EXAMPLES.items():
        scene = load_scene(SCENES / f"{name}.yaml")
        assert scene.robot == erd_model(relative).name
    for name, robot in BUNDLED_EXAMPLES.items():
        scene = load_scene(SCENES / f"{name}.yaml")
        assert scene.robot in (None, eomgen.load(eomgen.example_path(robot)).name)


# ----------------------------------------------------------------------------------------------
# Random trees with random locks, tips and payloads
# ----------------------------------------------------------------------------------------------


def random_scene(model: RobotModel, rng: np.random.Generator) -> str:
    """A scene text: sometimes tips (and a base above them), locks on some joints of the moving
    part and some outside it, a payload on a random link."""
    lines = ["version: 1"]
    parent = model.parent_joint
    movable = [j.name for j in model.movable_joints]
    candidates = movable
    if rng.random() < 0.6:
        leaves = sorted({j.child for j in model.joints} - {j.parent for j in model.joints})
        tips = list(rng.choice(leaves, size=min(len(leaves), int(rng.integers(1, 3))),
                               replace=False))

        def above(link):  # strict ancestors, nearest first
            out = []
            while link in parent:
                link = parent[link].parent
                out.append(link)
            return out

        common = [l for l in above(tips[0]) if all(l in above(t) for t in tips[1:])]
        base = common[int(rng.integers(len(common)))] if rng.random() < 0.5 else model.root
        lines += [f"base: {base}", "tips: [" + ", ".join(tips) + "]"]
        on_paths = set()
        for tip in tips:
            link = tip
            while link != base:
                on_paths.add(parent[link].name)
                link = parent[link].parent
        candidates = [j for j in movable if j in on_paths]
    inside = list(rng.choice(candidates, size=len(candidates) // 2, replace=False))
    outside = [j for j in movable if j not in candidates and rng.random() < 0.5]
    locks = inside + outside
    if locks:
        lines.append("locked: {" + ", ".join(f"{j}: {rng.uniform(-2, 2):.6f}" for j in locks)
                     + "}")
    return "\n".join(lines) + "\n"


def with_payload(text: str, model: RobotModel, rng: np.random.Generator) -> str:
    """``text`` with a payload on a link that moves (mostly: a link merged into a moving body
    through fixed or locked joints), or else on any link."""
    report = apply_scene(model, scene_text(text)).report
    merged = [name for body in report.merged for name in body.links]
    moving = [body.link for body in report.merged]
    choices = merged if merged and rng.random() < 0.6 else moving
    link = rng.choice(choices if rng.random() < 0.85 else [l.name for l in model.links])
    return text + ("payloads:\n"
                   f"  - {{link: {link}, mass: 1.25, com: [0.1, -0.2, 0.05], "
                   "inertia: {ixx: 0.03, iyy: 0.02, izz: 0.04, ixy: 0.001}}\n")


@pytest.mark.parametrize("seed", range(6))
def test_random_trees_with_random_locks_equal_pinocchio(seed):
    need("pinocchio")
    rng = np.random.default_rng(100 + seed)
    model = random_robot(rng, int(rng.integers(3, 7)), tree=True)
    try:
        scene = scene_text(with_payload(random_scene(model, rng), model, rng))
    except SceneError as exc:  # only fixed joints between base and tips: an error, no crash
        assert "nothing moves" in str(exc)
        return
    reduction = apply_scene(model, scene)
    reference = pin_reference(to_pinocchio(model), model, reduction, scene)
    Compared(reduction, reference).check(seed)
    assert reduction.model.joint_names == tuple(
        n for n in model.joint_names if n in set(reduction.report.moving))


def test_random_chain_with_base_and_tip_in_the_middle():
    need("pinocchio")
    model = random_robot(np.random.default_rng(7), 6, tree=False, fixed_links=True)
    chain = [j for j in model.topological_joints if j.type.is_movable]
    base, tip = chain[1].child, chain[4].child
    scene = scene_text(f"version: 1\nbase: {base}\ntips: [{tip}]\n"
                       f"locked: {{{chain[0].name}: 0.7, {chain[5].name}: -0.3}}\n")
    reduction = apply_scene(model, scene)
    assert set(reduction.model.joint_names) == {j.name for j in chain[2:5]}
    assert {j.name: j.listed for j in reduction.report.locked} == {
        chain[0].name: True, chain[1].name: False, chain[5].name: True}
    Compared(reduction, pin_reference(to_pinocchio(model), model, reduction, scene)).check(8)


# ----------------------------------------------------------------------------------------------
# The reduced model and the report
# ----------------------------------------------------------------------------------------------


def test_the_empty_scene_merges_fixed_joints_and_drops_what_is_fixed_to_the_world():
    model = erd_model(EXAMPLES["ur5_payload"])
    reduced, report = apply_scene(model)
    assert all(j.type.is_movable for j in reduced.joints)
    # one body on the world: the fixed frame moves to its joint (the world link is dropped too)
    assert [l.name for l in reduced.links] == ["scene_world"] + [j.child for j in reduced.joints]
    assert reduced.joints[0].origin == Transform() and "shoulder_pan_joint" in report.world
    assert report.dropped == ("world", "base_link", "base")  # the root first
    assert (report.before.links, report.after.links) == (11, 7)
    assert reduced.joint_names == model.joint_names and not report.locked
    # a body with one link keeps that link's numbers exactly
    assert reduced.link_by_name["wrist_1_link"] == model.link_by_name["wrist_1_link"]


def test_report_markdown_lists_steps_and_measured_costs():
    model = eomgen.load(eomgen.example_path("planar_2link"))
    reduction = apply_scene(model, scene_text("version: 1\nlocked: {joint2: 0.5}\n"
                                              "description: elbow held\noutputs: [g]\n"))
    from eomgen.codegen.derivation_cost import derivation_cost

    after = derivation_cost(derive(reduction.model, outputs=("g",)))
    text = reduction.report.markdown(None, after)
    assert "`joint2` at 0.5 (from the scene)" in text
    assert "| movable joints (dof) | 2 | 1 | 2.0× |" in text
    assert "| operations of g | – |" in text
    assert "`link2`" in text  # merged into link1
    assert "Outputs: `gravity_vector`." in text


def test_exact_zeros_stay_exact_and_cost_no_operations():
    """Locking at 0 keeps rotations exact; a payload at the body origin keeps the merged centre
    of mass exactly zero where the link's is; each gives fewer operations than the same scene
    with a small non-zero value."""
    arm = eomgen.load(eomgen.example_path("planar_2link"))

    def locked_at(position: str) -> RobotModel:
        return apply_scene(arm, scene_text(f"version: 1\nlocked: {{joint2: {position}}}\n"
                                           "symbolic: none\n")).model

    straight, bent = locked_at("0"), locked_at("0.3")
    assert straight.link_by_name["link1"].inertial.com[1:] == (0, 0)
    assert (derive(straight, outputs=("M", "g")).operation_count()
            < derive(bent, outputs=("M", "g")).operation_count())
    model = random_robot(np.random.default_rng(3), 4, tree=False, fixed_links=False)
    last = model.movable_joints[-1]
    zero_com = Inertial(2.0, (0, 0, 0), ((0.1, 0, 0), (0, 0.2, 0), (0, 0, 0.3)))
    links = tuple(l if l.name != last.child else Link(l.name, zero_com) for l in model.links)
    bare = dataclasses.replace(model, links=links)
    payload = "payloads: [{link: %s, mass: 1, com: [%s, 0, 0], inertia: {ixx: 0.1, iyy: 0.1, izz: 0.1}}]"
    exact, _ = apply_scene(bare, scene_text("version: 1\n" + payload % (last.child, 0)))
    assert exact.link_by_name[last.child].inertial.com == (0, 0, 0)
    assert exact.link_by_name[last.child].inertial.mass == 3
    offset, _ = apply_scene(bare, scene_text("version: 1\n" + payload % (last.child, 0.01)))
    assert (derive(exact, outputs=("M", "g")).operation_count()
            < derive(offset, outputs=("M", "g")).operation_count())


def test_planar_arm_is_recognised_and_gravity_along_the_axis_gives_zero_g():
    model = eomgen.load(eomgen.example_path("planar_2link"))
    _, report = apply_scene(model)
    assert report.planar is not None and report.planar.gravity == "in the plane"
    axis = report.planar.normal
    along = "[" + ", ".join(str(9.81 * a) for a in axis) + "]"
    reduced, report = apply_scene(model, scene_text(f"version: 1\ngravity: {along}\n"))
    assert report.planar.gravity == "along the normal"
    assert reduced.gravity == (0, 0, 0)
    assert list(derive(reduced, outputs=("g",)).g) == [0, 0]
    assert "g(q) ≡ 0" in report.markdown()


def test_a_spatial_arm_is_not_planar():
    assert planar_motion(erd_model(EXAMPLES["ur5_payload"])) is None


# ----------------------------------------------------------------------------------------------
# Only what is asked
# ----------------------------------------------------------------------------------------------


def test_scene_outputs_choose_what_is_derived_and_generated(tmp_path):
    robot = eomgen.example_path("planar_2link")
    scene = tmp_path / "g_only.yaml"
    scene.write_text("version: 1\noutputs: [g]\n")
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["generate", str(robot), "--scene", str(scene), "-o",
                                       str(out), "--backend", "numpy"])
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in out.iterdir()) == ["planar_2link_numpy.py",
                                                     "planar_2link_scene_report.md"]
    assert "deriving g of planar_2link" in result.stderr
    spec = importlib.util.spec_from_file_location("g_only", out / "planar_2link_numpy.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.__all__ == ["JOINT_NAMES", "CONFIGURATION_NAMES", "NQ", "NV", "PARAMETERS", "gravity_vector"]
    assert not hasattr(module, "coriolis_matrix") and not hasattr(module, "forward_dynamics")
    assert "Reduced by scene 'g_only.yaml'" in (out / "planar_2link_numpy.py").read_text()


def test_all_backends_leave_out_the_derivation_document_for_a_subset(tmp_path):
    scene = tmp_path / "s.yaml"
    scene.write_text("version: 1\noutputs: [forward_dynamics]\n")
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["generate", "--scene", str(scene), "-o", str(out),
                                       "--backend", "numpy,casadi"])
    assert result.exit_code == 0, result.output
    text = (out / "planar_2link_casadi.py").read_text()
    assert "coriolis_matrix" not in text and "forward_dynamics = _FUNCTIONS" in text
    result = CliRunner().invoke(main, ["generate", "--scene", str(scene), "-o", str(out),
                                       "--backend", "all"])
    assert result.exit_code == 0, result.output
    assert "latex: skipped (needs M, C, g)" in result.stderr
    result = CliRunner().invoke(main, ["generate", "--scene", str(scene), "-o",
                                       str(tmp_path / "none"), "--backend", "latex"])
    assert result.exit_code == 2 and not (tmp_path / "none").exists()


def test_explain_prints_the_report_with_both_derivations(tmp_path):
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["generate", "--explain", "-o", str(out), "--backend",
                                       "numpy", "--quiet"])
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith("# Scene report: planar_2link")
    assert "| operations of C |" in result.stdout and "| derivation time |" in result.stdout
    assert "not measured" not in result.stdout
    assert sorted(p.name for p in out.iterdir()) == ["planar_2link_numpy.py"]  # no scene file


def test_a_derivation_past_its_time_limit_is_reported_as_such():
    from eomgen.codegen.derivation_cost import measure_derivation

    model = eomgen.load(eomgen.example_path("planar_2link"))
    cost = measure_derivation(model, ("M", "C", "g"), timeout=0.05)
    assert cost.timeout == 0.05 and cost.seconds is None
    text = apply_scene(model).report.markdown(cost, None)
    assert "| derivation time | > 0.05 s (timeout) | not measured |" in text


# ----------------------------------------------------------------------------------------------
# Bad scenes
# ----------------------------------------------------------------------------------------------

BAD = {
    "unknown link": ("version: 1\ntips: [link3]\n", "tips[0] 'link3'", "did you mean"),
    "unknown base": ("version: 1\nbase: lnk1\n", "base 'lnk1'", "did you mean 'link1'"),
    "unknown joint": ("version: 1\nlocked: {joint9: 0}\n", "locked 'joint9'", "no joint"),
    "lock on a fixed joint": ("version: 1\nlocked: {fixed: 0}\n", "locked 'fixed'",
                              "cannot lock a fixed joint"),
    "tip not below base": ("version: 1\nbase: link2\ntips: [link1]\n", "tips[0] 'link1'",
                           "not below the base 'link2'"),
    "nothing moves": ("version: 1\nlocked: {joint1: 0, joint2: 0}\n", "locked", "nothing moves"),
    "negative mass": ("version: 1\npayloads: [{link: link2, mass: -1}]\n",
                      "payloads[0] 'payload0'", "negative"),
    "negative eigenvalue": ("version: 1\npayloads: [{link: link2, mass: 1, inertia: "
                            "{ixx: 1, iyy: 1, izz: -0.5}}]\n", "payloads[0] 'payload0'",
                            "negative eigenvalue"),
    "nan": ("version: 1\npayloads: [{link: link2, name: tool, mass: nan}]\n",
            "payloads[0] 'tool' mass", "not a finite number"),
    "payload on unknown link": ("version: 1\npayloads: [{link: hand, mass: 1}]\n",
                                "payloads[0] 'payload0' link", "no link 'hand'"),
    "unknown key": ("version: 1\nlockd: {joint1: 0}\n", "scene", "did you mean 'locked'"),
    "planned key": ("version: 1\nfriction: {joint1: 0.1}\n", "friction", "later scene version"),
    "no version": ("locked: {joint1: 0}\n", "scene", "missing required key 'version'"),
    "version 2": ("version: 2\n", "version", "not supported"),
    "unknown output": ("version: 1\noutputs: [M, Coriolis]\n", "outputs", "unknown output"),
    "unknown parameter": ("version: 1\nsymbolic: [lc3]\n", "symbolic 'lc3'", "did you mean"),
    "another robot": ("version: 1\nrobot: ur5\n", "robot", "not 'planar_2link_tool'"),
    "alias": ("version: 1\nbase: &b link1\ntips: [*b]\n", "", "aliases"),
}


@pytest.fixture(scope="module")
def arm():
    model = eomgen.load(eomgen.example_path("planar_2link"))
    tool = Link("tool", Inertial(0.5, (0.1, 0, 0), ((0.01, 0, 0), (0, 0.01, 0), (0, 0, 0.01))))
    joints = model.joints + (Joint("fixed", JointType.FIXED, "link2", "tool",
                                   Transform.from_xyz_rpy((0.3, 0, 0))),)
    return RobotModel(name="planar_2link_tool", links=model.links + (tool,), joints=joints,
                      root=model.root, gravity=model.gravity, parameters=model.parameters,
                      source="arm.yaml")


@pytest.mark.parametrize("case", list(BAD))
def test_bad_scene_is_one_line_naming_the_file_and_the_entry(arm, case):
    text, element, problem = BAD[case]
    with pytest.raises(SceneError) as caught:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            apply_scene(arm, scene_text(text, "bad_scene.yaml"))
    message = str(caught.value)
    assert isinstance(caught.value, DescriptionError)
    assert "\n" not in message and message.startswith("bad_scene.yaml: ")
    assert caught.value.element == element, message
    assert problem in message, message


def test_unknown_key_lists_the_known_ones():
    with pytest.raises(SceneError) as caught:
        scene_text("version: 1\nweight: 3\n")
    assert all(key in str(caught.value) for key in SCENE_KEYS)
    with pytest.raises(SceneError) as caught:
        scene_text("version: 1\narmature: {}\n")
    assert "armature" in PLANNED_KEYS and "later scene version" in str(caught.value)


@pytest.mark.parametrize("case", ["unknown joint", "negative eigenvalue", "tip not below base",
                                  "unknown key"])
def test_bad_scene_on_the_command_line_exits_2_and_writes_nothing(tmp_path, case):
    scene = tmp_path / "bad.yaml"
    scene.write_text(BAD[case][0].replace("fixed", "joint1"))
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["generate", "--scene", str(scene), "-o", str(out)])
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"eomgen: error: {scene}: ")
    assert not out.exists()


# ----------------------------------------------------------------------------------------------
# The documentation
# ----------------------------------------------------------------------------------------------

DOCS = ROOT / "docs" / "scenes.md"


def test_documented_example_is_the_shipped_scene():
    text = DOCS.read_text(encoding="utf-8")
    block = text.split("`examples/scenes/talos_left_arm.yaml`:\n\n```yaml\n", 1)[1].split("```")[0]
    shipped = "".join(line + "\n" for line in
                      (SCENES / "talos_left_arm.yaml").read_text().splitlines()
                      if not line.startswith("#"))
    assert block == shipped


def test_documented_error_lines_are_what_eomgen_prints():
    model = erd_model(EXAMPLES["ur5_payload"])
    text = DOCS.read_text(encoding="utf-8")
    documented = [line[len("eomgen: error: "):] for line in text.splitlines()
                  if line.startswith("eomgen: error: arm_scene.yaml")]
    scenes = ["locked: {elbow: 0}", "locked: {ee_fixed_joint: 0}",
              "base: wrist_1_link\ntips: [base_link]",
              "payloads: [{link: tool0, name: tool, mass: 1, inertia: {ixx: 1, iyy: 1, izz: -0.5}}]",
              "lockd: {elbow_joint: 0}"]
    printed = []
    for scene in scenes:
        with pytest.raises(SceneError) as caught:
            apply_scene(model, load_scene("arm_scene.yaml", text="version: 1\n" + scene))
        printed.append(str(caught.value))
    assert printed == documented


# ----------------------------------------------------------------------------------------------
# Warnings after the scene: only about what it keeps (mimic, triangle inequality, floating base)
# ----------------------------------------------------------------------------------------------

#: A 2-joint arm on a 'world' root with a two-finger gripper (finger2 mimics finger1), a second
#: arm whose link 'other' breaks the triangle inequality, a plate fixed to the world and a
#: sensor fixed to link1 that break it too.
_BAD_INERTIA = '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="3"/>'
_GOOD_INERTIA = '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'


def _urdf_link(name, inertia=_GOOD_INERTIA, mass=1.0):
    if inertia is None:
        return f'<link name="{name}"/>'
    return (f'<link name="{name}"><inertial><origin xyz="0.1 0 0"/><mass value="{mass}"/>'
            f'{inertia}</inertial></link>')


def _urdf_joint(name, parent, child, kind="revolute", xyz="0 0 0.1", axis="0 1 0", extra=""):
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{xyz}"/><axis xyz="{axis}"/>{extra}</joint>')


GRIPPER_ARM = "<robot name=\"gripper_arm\">" + "".join([
    _urdf_link("world", None), _urdf_link("link1"), _urdf_link("link2"),
    _urdf_link("finger1", mass=0.1), _urdf_link("finger2", mass=0.1),
    _urdf_link("other", _BAD_INERTIA), _urdf_link("plate", _BAD_INERTIA),
    _urdf_link("sensor", _BAD_INERTIA, mass=0.01),
    _urdf_joint("joint1", "world", "link1"), _urdf_joint("joint2", "link1", "link2", xyz="0.4 0 0"),
    _urdf_joint("finger_joint1", "link2", "finger1", "prismatic", "0.3 0 0"),
    _urdf_joint("finger_joint2", "link2", "finger2", "prismatic", "0.3 0 0", axis="0 -1 0",
                extra='<mimic joint="finger_joint1"/>'),
    _urdf_joint("other_joint", "world", "other", xyz="0 0.5 0.1"),
    _urdf_joint("plate_joint", "world", "plate", "fixed"),
    _urdf_joint("sensor_joint", "link1", "sensor", "fixed", "0.2 0 0"),
]) + "</robot>"


def gripper_arm():
    """The gripper arm with its follower finger read as independent (couplings=False), the
    notice deferred."""
    from eomgen.parsers import independent_followers
    from eomgen.parsers.urdf import parse_urdf_string

    model = parse_urdf_string(GRIPPER_ARM, source="gripper_arm.urdf", defer_notices=True)
    return independent_followers(model, defer_notices=True)


def kept(reduction: Reduction) -> list[str]:
    return [n.element for n in reduction.model.notices]


def test_the_parser_records_every_finding_in_file_order():
    model = gripper_arm()
    assert [(n.kind.name, n.element) for n in model.notices] == [
        ("TRIANGLE_INEQUALITY", "link 'other' inertial"),
        ("TRIANGLE_INEQUALITY", "link 'plate' inertial"),
        ("TRIANGLE_INEQUALITY", "link 'sensor' inertial"),
        ("MIMIC", "joint 'finger_joint2' <mimic>")]


@pytest.mark.parametrize("scene, expected", [
    # the fingers locked, the other arm outside the moving part (locked at 0, dropped)
    ("locked: {finger_joint1: 0.01, finger_joint2: 0.01}\ntips: [link2]",
     ["link 'sensor' inertial"]),  # merged into link1: its data still counts
    # the mimicked joint moves: reading finger2 as independent still matters
    ("locked: {finger_joint2: 0.01}\ntips: [finger1, finger2]",
     ["link 'sensor' inertial", "joint 'finger_joint2' <mimic>"]),
    # everything moves: all but the plate, which is fixed to the world
    ("description: every joint", ["link 'other' inertial", "link 'sensor' inertial",
                                  "joint 'finger_joint2' <mimic>"]),
])
def test_a_scene_keeps_the_notices_about_what_it_models(scene, expected):
    reduction = apply_scene(gripper_arm(), scene_text("version: 1\n" + scene))
    assert kept(reduction) == expected
    left_out = len(gripper_arm().notices) - len(expected)
    notes = [n for n in reduction.report.notes if n.startswith("warnings left out")]
    assert notes == [f"warnings left out, about what the scene locks or drops ({left_out}): "
                     + ", ".join(n.element for n in gripper_arm().notices
                                 if n.element not in expected)]


def test_fixed_base_silences_the_floating_base_and_nothing_else():
    talos = erd_model(EXAMPLES["talos_left_arm"])
    assert [n.kind.name for n in talos.notices] == ["FLOATING_BASE"]
    shipped = load_scene(SCENES / "talos_left_arm.yaml")
    assert shipped.fixed_base
    reduction = apply_scene(talos, shipped)
    assert reduction.model.notices == ()
    assert any(n.startswith("root link 'base_link': the scene says fixed_base: true")
               for n in reduction.report.notes)
    free = apply_scene(talos, dataclasses.replace(shipped, fixed_base=False, floating_base=True))
    assert free.model.notices == ()  # a free base is what the warning asked for
    assert any(n.startswith("the root link 'base_link' floats") for n in free.report.notes)
    unsaid = dataclasses.replace(shipped, fixed_base=False)  # every leg locked: still floating
    assert kept(apply_scene(talos, unsaid)) == ["root link 'base_link'"]
    everything = apply_scene(gripper_arm(), scene_text("version: 1\nfixed_base: true"))
    assert kept(everything) == ["link 'other' inertial", "link 'sensor' inertial",
                                "joint 'finger_joint2' <mimic>"]  # as without fixed_base


def test_fixed_base_must_be_true_or_false():
    with pytest.raises(SceneError) as caught:
        scene_text("version: 1\nfixed_base: yes please\n", "s.yaml")
    assert str(caught.value) == "s.yaml: fixed_base: expected true or false, got 'yes please'"
    assert scene_text("version: 1\nfixed_base: false\n").fixed_base is False


# Through the command line, in real processes ----------------------------------------------------

def warning_lines(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if line.startswith("eomgen: warning: ")]


def test_cli_warns_and_refuses_only_about_what_the_scene_keeps(tmp_path):
    description = tmp_path / "gripper_arm.urdf"
    description.write_text(GRIPPER_ARM, encoding="utf-8")
    fingers = tmp_path / "fingers.yaml"
    fingers.write_text("version: 1\nlocked: {finger_joint1: 0.01, finger_joint2: 0.01}\n"
                       "tips: [link2]\noutputs: [g]\n", encoding="utf-8")
    one_finger = tmp_path / "one_finger.yaml"
    one_finger.write_text("version: 1\nlocked: {finger_joint2: 0.01}\ntips: [finger1]\n"
                          "outputs: [g]\n", encoding="utf-8")
    common = ("--backend", "numpy", "--quiet")
    whole = run_process("generate", description, "-o", tmp_path / "a", *common)
    assert whole.returncode == 0, whole.stderr
    assert [line.split(": ")[3] for line in warning_lines(whole.stderr)] == [
        "link 'other' inertial", "link 'sensor' inertial"]  # without a scene: everything but
    # the plate, which never moves (fixed to the world), and the mimic finger, which follows
    locked = run_process("generate", description, "--scene", fingers, "-o", tmp_path / "b",
                         *common)
    assert locked.returncode == 0, locked.stderr
    assert warning_lines(locked.stderr) == [
        f"eomgen: warning: {description}: link 'sensor' inertial: principal moments 1, 1, 3 "
        "break the triangle inequality (not a physical rigid body)"]
    refused = run_process("generate", description, "--scene", one_finger, "-o", tmp_path / "c",
                          "--strict", *common)
    assert refused.returncode == 2 and not (tmp_path / "c").exists()
    assert refused.stderr.splitlines() == [  # finger2 follows finger1, which moves
        f"eomgen: error: {description}: joint 'finger_joint2': cannot lock a coupled joint "
        "while its leader 'finger_joint1' moves (joint 'finger_joint2' <mimic>): lock the "
        "leader"]


def test_cli_floating_base_warns_is_refused_and_silenced_by_fixed_base(tmp_path):
    from support.robots import legged

    description = tmp_path / "biped.urdf"
    description.write_text(legged(legs=2), encoding="utf-8")
    leg = "version: 1\ntips: [shin0]\noutputs: [g]\n"
    free, fixed = tmp_path / "leg.yaml", tmp_path / "leg_fixed.yaml"
    free.write_text(leg, encoding="utf-8")
    fixed.write_text(leg + "fixed_base: true\n", encoding="utf-8")
    common = ("--backend", "numpy", "--quiet")
    warned = run_process("generate", description, "--scene", free, "-o", tmp_path / "a", *common)
    assert warned.returncode == 0, warned.stderr
    assert [line[:80] for line in warning_lines(warned.stderr)] == [
        f"eomgen: warning: {description}: root link 'trunk': looks like a floating base"[:80]]
    refused = run_process("generate", description, "-o", tmp_path / "b", "--strict", *common)
    assert refused.returncode == 2 and not (tmp_path / "b").exists()
    assert refused.stderr.splitlines()[0].startswith(
        f"eomgen: error: {description}: root link 'trunk': looks like a floating base")
    silenced = run_process("generate", description, "--scene", fixed, "-o", tmp_path / "c",
                           "--strict", *common)
    assert silenced.returncode == 0, silenced.stderr
    assert silenced.stderr == ""


def test_floating_base_counts_the_described_joints_and_the_virtual_ones_apart(tmp_path):
    """Issue 29: a floating A1's scene log said "18 of 12 joints move"; the log, the generated
    module's header and the handout count the description's joints and the six virtual ones."""
    from support import run_in_process
    from support.robots import legged

    description = tmp_path / "biped.urdf"
    description.write_text(legged(legs=2), encoding="utf-8")
    scene = tmp_path / "fly.yaml"
    scene.write_text("version: 1\nfloating_base: true\noutputs: [g]\n", encoding="utf-8")
    result = run_in_process("generate", description, "--scene", scene, "--backend", "numpy",
                            "-o", tmp_path / "out", "--no-cache")
    assert result.returncode == 0, result.stderr
    said = "4 of 4 joints move, and the floating base's 6 virtual joints (10 in all)"
    assert f"scene fly.yaml: {said}, " in result.stderr
    assert f"{said}; see the scene report." in next((tmp_path / "out").glob("*_numpy.py")
                                                    ).read_text(encoding="utf-8")
    report = apply_scene(eomgen.load(description), load_scene(scene)).report
    assert report.moving_described == 4 and len(report.moving) == 10
    plain = apply_scene(eomgen.load(description), Scene(tips=("shin0",))).report
    assert plain.moving_summary() == "2 of 4 joints move"


@pytest.mark.slow
def test_cli_panda_with_its_mimic_finger_locked_passes_strict(tmp_path):
    """The issue's case: panda_fingers_locked.yaml locks both fingers (finger2 <mimic>
    finger1, at the position its coupling gives), nothing warns."""
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    panda = robots / EXAMPLES["panda_fingers_locked"]
    result = run_process("generate", panda, "--scene", SCENES / "panda_fingers_locked.yaml",
                         "--backend", "numpy", "-o", tmp_path / "out", "--strict", "--quiet")
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
    report = (tmp_path / "out" / "panda_scene_report.md").read_text(encoding="utf-8")
    assert "<mimic>" not in report
