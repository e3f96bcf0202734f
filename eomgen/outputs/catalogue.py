"""The catalogue of outputs: what each function of a generated module computes, as data.

Each :class:`Output` says what a function of a generated module computes: its name in the
module (``function``), the symbol of the derived quantity it returns (``symbol``, also accepted
as a short name), its inputs, shape, units and docstring line, what it needs derived, the
module constants it brings, the backends that compose it and whether it is derived for
quaternion joints. :data:`CATALOGUE` lists them in module order; :mod:`eomgen.outputs` indexes
them (``OUTPUTS``, ``BY_SYMBOL``) and answers the questions asked of them (``select``).

This module is data only: it imports nothing of eomgen and names no function, so every layer
may read it (docs/architecture.md, layer 0). Who builds a symbol, how long an input of
:data:`INPUT_SIZES` is and the values of the module constants are registered by the modules
that compute them (:mod:`eomgen.symbolic.builders`). Adding an output is one entry here and,
in the module that builds it, a builder decorated with ``@builds(symbol)``.
"""

from __future__ import annotations

# the record type and the inputs, re-exported: eomgen.outputs reads them from here
from .record import INPUT_SIZES, INPUTS, Output  # noqa: F401

_ENTRIES: list[Output] = []


def _listed(output: Output) -> Output:
    """``output``, listed in :data:`CATALOGUE` after the entries before it."""
    _ENTRIES.append(output)
    return output


_REVOLUTE_EFFORT = "N m (revolute), N (prismatic)"
# M, C and g (and the potential energy P) come from one Lagrangian program
# (eomgen.symbolic.routes), tau from Newton-Euler (eomgen.symbolic.newton_euler).
MASS = _listed(Output(
    "mass_matrix", "M", "Mass matrix M(q), symmetric positive definite.", ("q",), False,
    "kg m^2 (revolute rows/columns), kg (prismatic)", ("M",)))
CORIOLIS = _listed(Output(
    "coriolis_matrix", "C", "Coriolis matrix C(q, qd) from the Christoffel symbols of the first "
    "kind, so that Mdot - 2 C is skew-symmetric.", ("q", "qd"), False, "kg m^2/s (revolute)",
    ("C",)))
GRAVITY = _listed(Output(
    "gravity_vector", "g", "Gravity vector g(q) = dP/dq.", ("q",), True, _REVOLUTE_EFFORT,
    ("g",)))
INVERSE = _listed(Output(
    "inverse_dynamics", "tau", "Joint efforts tau = M(q) qdd + C(q, qd) qd + g(q) "
    "(recursive Newton-Euler, straight-line).", ("q", "qd", "qdd"), True, _REVOLUTE_EFFORT,
    ("tau",)))
FORWARD = _listed(Output(
    "forward_dynamics", None, "Joint accelerations qdd solving M(q) qdd = tau - (C(q, qd) qd "
    "+ g(q)) by Cholesky.", ("q", "qd", "tau"), True, "rad/s^2 (revolute), m/s^2 (prismatic)",
    ("M", "tau"), composed_from=(MASS.function, INVERSE.function)))

# Issue 18: O(n) algorithms, exported when asked for (``--outputs qdd_aba,h``).
FORWARD_ABA = _listed(Output(
    "forward_dynamics_aba", "qdd_aba", "Joint accelerations qdd of M(q) qdd + C(q, qd) qd + "
    "g(q) = tau by the Articulated-Body Algorithm (O(n), straight-line, no factorisation).",
    ("q", "qd", "tau"), True, "rad/s^2 (revolute), m/s^2 (prismatic)", ("qdd_aba",), default=False))
NONLINEAR = _listed(Output(
    "nonlinear_effects", "h", "Nonlinear effects h(q, qd) = C(q, qd) qd + g(q) (Newton-Euler "
    "with qdd = 0; C itself is not formed).", ("q", "qd"), True, _REVOLUTE_EFFORT, ("h",),
    default=False))

# Issue 17: drives and flexible joints (docs/actuators.md), exported when asked for.
DRIVE_MASS = _listed(Output(
    "drive_mass_matrix", "M_a", "Mass matrix with the drives' armature, M(q) + diag(a) (every "
    "joint stiff).", ("q",), False, "kg m^2 (revolute rows/columns), kg (prismatic)", ("M_a",),
    default=False))
FRICTION = _listed(Output(
    "friction_torque", "tau_f", "Friction torque of the drives d qd + f sign(qd) (exact sign, "
    "for inverse dynamics).", ("qd",), True, _REVOLUTE_EFFORT, ("tau_f",),
    default=False))
FRICTION_SMOOTH = _listed(Output(
    "friction_torque_smooth", "tau_f_smooth", "Friction torque of the drives d qd + f tanh(qd / "
    "w) (Coulomb smoothed with the width w, for simulation).", ("qd",), True, _REVOLUTE_EFFORT,
    ("tau_f_smooth",), default=False))
DRIVE_INVERSE = _listed(Output(
    "drive_inverse_dynamics", "tau_a", "Drive torques (M(q) + diag(a)) qdd + C(q, qd) qd + g(q) "
    "+ d qd + f sign(qd).", ("q", "qd", "qdd"), True, _REVOLUTE_EFFORT, ("tau_a",), default=False))
LINK_MASS = _listed(Output(
    "link_mass_matrix", "M_l", "Link mass matrix of the flexible-joint model, M(q) + diag(a) of "
    "the rigid joints only.", ("q",), False, "kg m^2 (revolute rows/columns), kg (prismatic)",
    ("M_l",), default=False))
SPRING = _listed(Output(
    "spring_torque", "tau_K", "Torque the joint springs pass to the links, K (theta_m - q) on "
    "flexible joints, 0 on rigid ones.", ("q", "theta_m"), True, _REVOLUTE_EFFORT, ("tau_K",),
    default=False))
MOTOR_FORWARD = _listed(Output(
    "motor_forward_dynamics", "thetadd_m", "Motor accelerations (tau - K (theta_m - q) - d "
    "thetad_m - f tanh(thetad_m / w)) / B of flexible joints (0 for rigid ones); tau is the "
    "motor torque.",
    ("q", "theta_m", "thetad_m", "tau"), True, "rad/s^2", ("thetadd_m",),
    default=False))

# Issue 15: the joint torque regressor tau = Y(q, qd, qdd) pi, the description's parameters pi,
# the base regressor and base parameters (Y pi = Y_base beta), and the energy regressors; all
# built in one call (eomgen.regressor.generated; see docs/regressor.md).
_PER_PARAMETER = "N m (revolute rows), N (prismatic) per unit of each column's parameter"
_NAMES, _BASE_NAMES = ("PARAMETER_NAMES",), ("PARAMETER_NAMES", "BASE_PARAMETER_NAMES")
REGRESSOR = _listed(Output(
    "regressor", "Y", "Joint torque regressor Y(q, qd, qdd), n x p: tau = Y pi, columns "
    "PARAMETER_NAMES (per body m, m c, inertia about the body origin; then actuator terms).",
    ("q", "qd", "qdd"), False, _PER_PARAMETER, ("Y",), default=False,
    constants=_NAMES))
INERTIAL_PARAMETERS = _listed(Output(
    "inertial_parameters", "pi", "The description's standard parameters pi, (p,), in "
    "PARAMETER_NAMES order.", (), True,
    "kg, kg m, kg m^2; armature kg m^2, viscous N m s/rad, Coulomb N m", ("pi",), default=False,
    constants=_NAMES))
BASE_REGRESSOR = _listed(Output(
    "base_regressor", "Y_base", "Base regressor Y_base(q, qd, qdd), n x b, full column rank: "
    "tau = Y_base beta, columns BASE_PARAMETER_NAMES.", ("q", "qd", "qdd"), False,
    _PER_PARAMETER, ("Y_base",), default=False, constants=_BASE_NAMES))
BASE_PARAMETERS = _listed(Output(
    "base_parameters", "beta", "The description's base parameters beta, (b,), in "
    "BASE_PARAMETER_NAMES order: the identifiable combinations of pi.", (), True,
    "the units of the parameter each groups into", ("beta",), default=False,
    constants=_BASE_NAMES))
KINETIC_REGRESSOR = _listed(Output(
    "kinetic_energy_regressor", "Y_K", "Kinetic energy regressor Y_K(q, qd), (p,): K = Y_K . pi "
    "(actuator columns 0).", ("q", "qd"), True, "J per unit of each column's parameter",
    ("Y_K",), default=False, constants=_NAMES))
POTENTIAL_REGRESSOR = _listed(Output(
    "potential_energy_regressor", "Y_P", "Potential energy regressor Y_P(q), (p,): P = Y_P . pi "
    "= -sum m g_vec . c over the moving bodies (actuator columns 0).", ("q",), True,
    "J per unit of each column's parameter", ("Y_P",), default=False,
    constants=_NAMES))

# Issue 17: the flat inverse dynamics of Spong's flexible-joint model (docs/actuators.md): motor
# states and torques that make the links follow q(t), from q and its derivatives up to order 4.
MOTOR_ANGLES = _listed(Output(
    "motor_angles", "theta_flat", "Motor angles (link side of the gear) that make the links "
    "follow q(t): q + K^-1 tau_L on flexible joints, q on rigid ones; tau_L = M qdd + C qd + g.",
    ("q", "qd", "qdd"), True, "rad (revolute), m (prismatic)", ("theta_flat",),
    default=False))
MOTOR_VELOCITIES = _listed(Output(
    "motor_velocities", "thetad_flat", "Motor velocities that make the links follow q(t): qd + "
    "K^-1 d/dt tau_L on flexible joints, qd on rigid ones.", ("q", "qd", "qdd", "qddd"), True,
    "rad/s (revolute), m/s (prismatic)", ("thetad_flat",), default=False))
FLAT_TORQUE = _listed(Output(
    "flat_motor_torque", "tau_flat", "Inputs tau that make the links follow q(t) (flatness): "
    "B thetadd + K (theta - q) + d thetad + f sign(thetad) on flexible joints (motor torque), "
    "tau_L + a qdd + d qd + f sign(qd) on rigid ones.", ("q", "qd", "qdd", "qddd", "qdddd"), True,
    _REVOLUTE_EFFORT, ("tau_flat",), default=False))
FLAT_TORQUE_SMOOTH = _listed(Output(
    "flat_motor_torque_smooth", "tau_flat_smooth", "Inputs tau that make the links follow "
    "q(t), as flat_motor_torque but with Coulomb friction f tanh(v / w) in place of f sign(v) "
    "(the law of motor_forward_dynamics: a simulation fed with it follows q(t)).", ("q", "qd", "qdd", "qddd", "qdddd"), True, _REVOLUTE_EFFORT,
    ("tau_flat_smooth",), default=False))


# Issue 18: several results from one program, sharing its work (``--outputs dynamics``).
DYNAMICS = _listed(Output(
    "dynamics", "MCg", "M(q), C(q, qd) and g(q) in one call: one program shares their work "
    "(sines, rotations, recursions).", ("q", "qd"), False,
    "the units of mass_matrix, coriolis_matrix and gravity_vector", ("MCg",),
    default=False,
    returns=(MASS.symbol, CORIOLIS.symbol, GRAVITY.symbol)))
MASS_AND_BIAS = _listed(Output(
    "mass_matrix_and_bias", "Mh", "M(q) and h(q, qd) = C(q, qd) qd + g(q) in one call (what "
    "forward dynamics and computed-torque control need): one program shares their work.",
    ("q", "qd"), False, "the units of mass_matrix and nonlinear_effects", ("Mh",), default=False,
    returns=(MASS.symbol, NONLINEAR.symbol)))


# --- issue 27: centroidal quantities (eomgen.symbolic.centroidal) ----------------------------
CENTER_OF_MASS = _listed(Output(
    "center_of_mass", "c_G", "Centre of mass c of the robot in world coordinates: (3,).",
    ("q",), True, "m", ("c_G",), default=False))
CENTER_OF_MASS_JACOBIAN = _listed(Output(
    "center_of_mass_jacobian", "J_G", "Jacobian of the centre of mass, cdot = J_G qd: (3, n).",
    ("q",), False, "m/rad or 1", ("J_G",), default=False))
CENTROIDAL_MAP = _listed(Output(
    "centroidal_momentum_matrix", "A_G", "Centroidal momentum matrix A_G, h_G = A_G qd = "
    "[linear; angular momentum about the centre of mass], world axes: (6, n).", ("q",), False,
    "kg m/rad or kg (linear rows), kg m^2/rad or kg m (angular rows)", ("A_G",), default=False))
CENTROIDAL_BIAS = _listed(Output(
    "centroidal_momentum_bias", "dAGv", "Centroidal momentum bias A_G-dot qd: the rate of h_G "
    "at qdd = 0, [linear; angular]: (6,).", ("q", "qd"), True, "N, N m", ("dAGv",), default=False))
CENTROIDAL_INERTIA = _listed(Output(
    "centroidal_composite_inertia", "I_G", "Centroidal composite inertia [[m 1, 0], [0, I_c]], "
    "I_c the rotational inertia about the centre of mass in world axes: (6, 6).", ("q",),
    False, "kg (upper block), kg m^2 (lower block)", ("I_G",),
    default=False))


# --- issue 16: frame kinematics and contacts (eomgen.symbolic.frames) -----------------------
_FRAME_NAMES = ("FRAME_NAMES",)
# the contact rows, then the loop rows (eomgen.symbolic.loops): J_c, F_c cover both
_CONTACT_NAMES = ("CONTACT_NAMES", "CONTACT_ROWS")
_LOOP_NAMES = ("LOOP_NAMES", "LOOP_ROWS")
_PYRAMID_NAMES = ("CONTACT_NAMES", "PYRAMID_ROWS")
FRAME_POSITIONS = _listed(Output(
    "frame_positions", "p_f", "Frame origins in world coordinates, one row per frame of "
    "FRAME_NAMES: (nf, 3).", ("q",), False, "m", ("p_f",), default=False,
    constants=_FRAME_NAMES))
FRAME_ROTATIONS = _listed(Output(
    "frame_rotations", "R_f", "Frame rotations R (x_world = R x_frame + p), 3x3 blocks stacked "
    "in FRAME_NAMES order: (3 nf, 3).", ("q",), False, "1", ("R_f",),
    default=False, constants=_FRAME_NAMES))
FRAME_JACOBIANS = _listed(Output(
    "frame_jacobians", "J_f", "World-aligned frame Jacobians at the frame origins, [linear; "
    "angular]: [pdot; omega] = J qd, 6xn blocks in FRAME_NAMES order: (6 nf, n).", ("q",), False,
    "m/rad (linear rows), 1 (angular rows)", ("J_f",), default=False,
    constants=_FRAME_NAMES))
FRAME_BODY_JACOBIANS = _listed(Output(
    "frame_body_jacobians", "Jb_f", "Body frame Jacobians, [linear; angular] in frame axes: "
    "[R^T pdot; R^T omega] = Jb qd, 6xn blocks in FRAME_NAMES order: (6 nf, n).", ("q",), False,
    "m/rad (linear rows), 1 (angular rows)", ("Jb_f",), default=False,
    constants=_FRAME_NAMES))
FRAME_JACOBIANS_DOT_QD = _listed(Output(
    "frame_jacobians_dot_qd", "dJqd_f", "Jdot qd of the world-aligned frame Jacobians: the "
    "frame accelerations [pddot; omegadot] at qdd = 0, FRAME_NAMES order: (6 nf,).",
    ("q", "qd"), True, "m/s^2, rad/s^2", ("dJqd_f",), default=False,
    constants=_FRAME_NAMES))
CONTACT_JACOBIAN = _listed(Output(
    "contact_jacobian", "J_c", "Contact Jacobian J_c (m, n): the rows of the scene's contacts "
    "(point: world-aligned linear rows; surface: body rows), then of its loops (J_l), "
    "CONTACT_ROWS order.", ("q",), False,
    "m/rad (force rows), 1 (moment rows)", ("J_c",), default=False,
    constants=_CONTACT_NAMES))
LOOP_CONSTRAINT = _listed(Output(
    "loop_constraint", "Phi_l", "Loop closure error Phi_l(q) (m_l,), zero on closed loops: "
    "frame b less frame a, LOOP_ROWS order (eomgen.symbolic.loops).", ("q",), True,
    "m (translational rows), 1 (rotational rows: sines)", ("Phi_l",), default=False,
    constants=_LOOP_NAMES))
LOOP_JACOBIAN = _listed(Output(
    "loop_jacobian", "J_l", "Loop Jacobian J_l(q) (m_l, n): the velocity of each loop's frame "
    "b relative to its frame a in the rows' axes, J_l qd, LOOP_ROWS order.", ("q",), False,
    "m/rad (translational rows), 1 (rotational rows)", ("J_l",), default=False,
    constants=_LOOP_NAMES))
LOOP_BIAS = _listed(Output(
    "loop_bias", "dJqd_l", "Loop bias J_l-dot qd (m_l,): the loops' relative accelerations at "
    "qdd = 0, LOOP_ROWS order.", ("q", "qd"), True, "m/s^2, rad/s^2", ("dJqd_l",), default=False,
    constants=_LOOP_NAMES))
CONTACT_BIAS = _listed(Output(
    "contact_bias", "dJqd_c", "Contact bias J_c-dot qd (m,): the constraint accelerations at "
    "qdd = 0, CONTACT_ROWS order.", ("q", "qd"), True, "m/s^2, rad/s^2", ("dJqd_c",),
    default=False, constants=_CONTACT_NAMES))
FRAME_BODY_JACOBIANS_DOT_QD = _listed(Output(
    "frame_body_jacobians_dot_qd", "dJbqd_f", "Jdot qd of the body frame Jacobians: the time "
    "derivative of the body twist [v_b; omega_b] at qdd = 0, [R^T pddot - omega_b x v_b; R^T "
    "omegadot], FRAME_NAMES order: (6 nf,).", ("q", "qd"), True, "m/s^2, rad/s^2", ("dJbqd_f",),
    default=False, constants=_FRAME_NAMES))
CONTACT_INVERSE = _listed(Output(
    "contact_inverse_dynamics", "tau_c", "Joint efforts tau = M(q) qdd + C(q, qd) qd + g(q) - "
    "J_c(q)^T F_c giving qdd while the contacts push on the robot with F_c (CONTACT_ROWS, the "
    "axes of contact_jacobian's rows).", ("q", "qd", "qdd", "F_c"), True, _REVOLUTE_EFFORT,
    ("tau_c",), default=False,
    constants=_CONTACT_NAMES))
FRICTION_CONE = _listed(Output(
    "friction_cone_margin", "cone_c", "Exact friction-cone margins mu f_n - |f_t| of the "
    "contact forces F_c, one per contact (CONTACT_NAMES): >= 0 inside the cone.", ("F_c",),
    True, "N", ("cone_c",), default=False,
    constants=_PYRAMID_NAMES))
FRICTION_PYRAMID = _listed(Output(
    "friction_pyramid_margins", "pyramid_c", "Margins of the inscribed four-sided friction "
    "pyramid, mu/sqrt(2) f_n -/+ f_t1 and -/+ f_t2 per contact (PYRAMID_ROWS), linear in F_c: "
    "all >= 0 inside.", ("F_c",), True, "N", ("pyramid_c",), default=False,
    constants=_PYRAMID_NAMES))
CONSTRAINED_FORWARD = _listed(Output(
    "constrained_forward_dynamics", None, "(qdd, F_c) holding every contact: the KKT system "
    "[[M, -J_c^T], [J_c, 0]] [qdd; F_c] = [tau - (C qd + g); -J_c-dot qd].",
    ("q", "qd", "tau"), True, "rad/s^2, m/s^2; N, N m", ("M", "tau", "J_c", "dJqd_c"),
    composed_from=(MASS.function, INVERSE.function, CONTACT_JACOBIAN.function,
                   CONTACT_BIAS.function), default=False, constants=_CONTACT_NAMES))

PARALLEL_INVERSE = _listed(Output(
    "parallel_inverse_dynamics", None, "(tau, lambda) of a parallel robot: joint efforts zero "
    "on the passive joints (ACTUATED_JOINTS carry them) and loop forces (LOOP_ROWS) with "
    "M qdd + C qd + g = tau + J_l^T lambda, for a qdd consistent with the loops.",
    ("q", "qd", "qdd"), True, "N m, N; N, N m", (INVERSE.symbol, "J_l"),
    composed_from=(INVERSE.function, LOOP_JACOBIAN.function), default=False,
    constants=("ACTUATED_JOINTS", "LOOP_ROWS"),
    backends=("numpy", "fast", "casadi", "c", "jax", "torch")))

# Issue 28: the Slotine-Li regressor Y_SL(q, qd, qd_r, qdd_r) pi = M qdd_r + C(q, qd) qd_r + g
# (C Christoffel) and its base columns, for adaptive control (docs/control.md).
SLOTINE_LI_REGRESSOR = _listed(Output(
    "slotine_li_regressor", "Y_SL", "Slotine-Li regressor Y_SL(q, qd, qd_r, qdd_r), n x p: "
    "Y_SL pi = M qdd_r + C(q, qd) qd_r + g (Christoffel C), columns PARAMETER_NAMES.",
    ("q", "qd", "qd_r", "qdd_r"), False, _PER_PARAMETER, ("Y_SL",),
    default=False, constants=_NAMES))
SLOTINE_LI_BASE_REGRESSOR = _listed(Output(
    "slotine_li_base_regressor", "Y_SL_base", "Base Slotine-Li regressor, n x b: Y_SL_base "
    "beta = Y_SL pi, columns BASE_PARAMETER_NAMES.", ("q", "qd", "qd_r", "qdd_r"), False,
    _PER_PARAMETER, ("Y_SL_base",), default=False, constants=_BASE_NAMES))


# --- issue 25: exact derivatives of the dynamics (eomgen.symbolic.derivatives); derivatives
# with respect to q are along the tangent (nv columns: eomgen.symbolic.tangent).
_PER_Q = "of the joint efforts per rad (revolute columns) or m (prismatic)"
DTAU_DQ = _listed(Output(
    "inverse_dynamics_derivative_q", "dtau_dq", "dtau/dq (n, nv) of tau(q, qd, qdd) "
    "(Newton-Euler differentiated in forward mode).", ("q", "qd", "qdd"), False, _PER_Q,
    ("dtau_dq",), default=False))
DTAU_DQD = _listed(Output(
    "inverse_dynamics_derivative_qd", "dtau_dqd", "dtau/dqd (n, nv) of tau(q, qd, qdd).",
    ("q", "qd", "qdd"), False, "of the joint efforts per rad/s or m/s", ("dtau_dqd",),
    default=False))
INVERSE_DERIVATIVES = _listed(Output(
    "inverse_dynamics_derivatives", "dtau", "(dtau/dq, dtau/dqd) of tau(q, qd, qdd) in one "
    "call (dtau/dqdd is M).", ("q", "qd", "qdd"), False,
    "the units of inverse_dynamics_derivative_q and _qd", ("dtau",),
    default=False, returns=("dtau_dq", "dtau_dqd")))
GRAVITY_DERIVATIVE = _listed(Output(
    "gravity_derivative", "dg_dq", "dg/dq (n, nv) of the gravity vector g(q).", ("q",), False,
    _PER_Q, ("dg_dq",), default=False))
DQDD_DQ = _listed(Output(
    "forward_dynamics_derivative_q", "dqdd_dq", "dqdd/dq (nv, nv) of qdd(q, qd, tau) = -M^-1 "
    "dtau/dq at qdd(q, qd, tau).", ("q", "qd", "tau"), False, "1/s^2", ("dqdd_dq",), default=False))
DQDD_DQD = _listed(Output(
    "forward_dynamics_derivative_qd", "dqdd_dqd", "dqdd/dqd (nv, nv) of qdd(q, qd, tau) = "
    "-M^-1 dtau/dqd at qdd(q, qd, tau).", ("q", "qd", "tau"), False, "1/s", ("dqdd_dqd",),
    default=False))
INVERSE_MASS = _listed(Output(
    "inverse_mass_matrix", "Minv", "M(q)^-1 = dqdd/dtau (nv, nv), from the "
    "straight-line L^T D L factors of M.", ("q",), False, "1/(kg m^2) (revolute), 1/kg (prismatic)",
    ("Minv",), default=False))
FORWARD_DERIVATIVES = _listed(Output(
    "forward_dynamics_derivatives", "dqdd", "(dqdd/dq, dqdd/dqd, M^-1 = dqdd/dtau) of "
    "qdd(q, qd, tau) in one call.", ("q", "qd", "tau"), False,
    "the units of forward_dynamics_derivative_q, _qd and inverse_mass_matrix", ("dqdd",),
    default=False, returns=("dqdd_dq", "dqdd_dqd", "Minv")))
STATE_MATRIX = _listed(Output(
    "state_matrix", "A_lin", "A = df/dx (2 nv, 2 nv) of xdot = f(x, tau), x = (q, qd): "
    "[[T, I], [dqdd/dq, dqdd/dqd]], T = 0 (quaternion joints: -ad_v / 2, the tangent chart's).",
    ("q", "qd", "tau"), False, "1, 1/s, 1/s^2",
    ("A_lin",), default=False, width=2))
INPUT_MATRIX = _listed(Output(
    "input_matrix", "B_lin", "B = df/dtau (2 nv, nv) of xdot = f(x, tau): [[0], [M^-1]].",
    ("q", "qd", "tau"), False, "1/(kg m^2) (revolute)", ("B_lin",),
    default=False))
LINEARIZE = _listed(Output(
    "linearize", "AB", "(A, B) of xdot = f(x, tau) ~ A dx + B dtau, x = (q, qd), in one call.",
    ("q", "qd", "tau"), False, "the units of state_matrix and input_matrix", ("AB",),
    default=False, returns=("A_lin", "B_lin")))
# with the drives of issue 17 (armature a, viscous d and Coulomb f friction; docs/actuators.md)
DRIVE_DTAU_DQD = _listed(Output(
    "drive_inverse_dynamics_derivative_qd", "dtau_a_dqd", "dtau_a/dqd (n, nv) of the drive "
    "torques tau_a = tau + a qdd + d qd + f sign(qd): dtau/dqd + diag(d) (sign: 0 at qd != 0).",
    ("q", "qd", "qdd"), False, "of the joint efforts per rad/s or m/s", ("dtau_a_dqd",),
    default=False))
DRIVE_INVERSE_DERIVATIVES = _listed(Output(
    "drive_inverse_dynamics_derivatives", "dtau_a", "(dtau_a/dq, dtau_a/dqd) of the drive "
    "torques in one call (dtau_a/dq is dtau/dq).", ("q", "qd", "qdd"), False,
    "the units of inverse_dynamics_derivative_q and _qd", ("dtau_a",),
    default=False, returns=("dtau_dq", "dtau_a_dqd")))
DRIVE_DQDD_DQ = _listed(Output(
    "drive_forward_dynamics_derivative_q", "dqdd_a_dq", "dqdd/dq (nv, nv) of the drives' "
    "qdd = (M + diag(a))^-1 (tau - C qd - g - d qd - f tanh(qd / w)).", ("q", "qd", "tau"),
    False, "1/s^2", ("dqdd_a_dq",), default=False))
DRIVE_DQDD_DQD = _listed(Output(
    "drive_forward_dynamics_derivative_qd", "dqdd_a_dqd", "dqdd/dqd (nv, nv) of the drives' "
    "forward dynamics (friction included).", ("q", "qd", "tau"), False, "1/s",
    ("dqdd_a_dqd",), default=False))
DRIVE_INVERSE_MASS = _listed(Output(
    "drive_inverse_mass_matrix", "Minv_a", "(M(q) + diag(a))^-1 = dqdd/dtau (nv, nv) of the "
    "drives' forward dynamics (the factors of M + diag(a)).", ("q",), False,
    "1/(kg m^2) (revolute), 1/kg (prismatic)", ("Minv_a",), default=False))
DRIVE_FORWARD_DERIVATIVES = _listed(Output(
    "drive_forward_dynamics_derivatives", "dqdd_a", "(dqdd/dq, dqdd/dqd, (M + diag(a))^-1) of "
    "the drives' forward dynamics in one call.", ("q", "qd", "tau"), False,
    "the units of drive_forward_dynamics_derivative_q, _qd and drive_inverse_mass_matrix",
    ("dqdd_a",), default=False,
    returns=("dqdd_a_dq", "dqdd_a_dqd", "Minv_a")))

# Issue 42: second derivatives of the inverse dynamics (eomgen.symbolic.second_derivatives), in
# the layout of Pinocchio's ComputeRNEASecondOrderDerivatives; no quaternion joints yet.
_TENSOR = ("a tensor T[i, j, k] returned as (n, nv*nv), entry [i, j*nv + k]: reshape(n, nv, "
           "nv) gives T.")
D2TAU_DQDQ = _listed(Output(
    "inverse_dynamics_second_derivative_q", "d2tau_dqdq", "d2tau/dq2 of tau(q, qd, qdd): "
    "d2tau_dqdq[i, j, k] = d2tau_i/dq_j dq_k, " + _TENSOR, ("q", "qd", "qdd"), False,
    "of the joint efforts per rad^2 (revolute columns) or m^2", ("d2tau_dqdq",), default=False,
    on_charts=False, tensor=True))
D2TAU_DVDV = _listed(Output(
    "inverse_dynamics_second_derivative_qd", "d2tau_dvdv", "d2tau/dqd2 of tau(q, qd, qdd): "
    "d2tau_dvdv[i, j, k] = d2tau_i/dqd_j dqd_k, " + _TENSOR, ("q", "qd", "qdd"), False,
    "of the joint efforts per (rad/s)^2 or (m/s)^2", ("d2tau_dvdv",), default=False,
    on_charts=False, tensor=True))
DTAU_DQDV = _listed(Output(
    "inverse_dynamics_second_derivative_q_qd", "dtau_dqdv", "d(dtau/dq)/dqd of tau(q, qd, "
    "qdd): dtau_dqdv[i, j, k] = d2tau_i/dq_j dqd_k, " + _TENSOR, ("q", "qd", "qdd"), False,
    "of the joint efforts per rad (revolute j) and rad/s (revolute k)", ("dtau_dqdv",),
    default=False, on_charts=False, tensor=True))
DTAU_DADQ = _listed(Output(
    "mass_matrix_derivative_q", "dtau_dadq", "dM/dq = d(dtau/dqdd)/dq: dtau_dadq[i, j, k] = "
    "dM_ij/dq_k, " + _TENSOR, ("q",), False, "kg m^2 per rad (revolute)", ("dtau_dadq",),
    default=False, on_charts=False, tensor=True))
SECOND_DERIVATIVES = _listed(Output(
    "inverse_dynamics_second_derivatives", "d2tau", "(d2tau_dqdq, d2tau_dvdv, dtau_dqdv, "
    "dtau_dadq) of tau(q, qd, qdd) in one call, each (n, nv*nv) as in Pinocchio's "
    "ComputeRNEASecondOrderDerivatives.", ("q", "qd", "qdd"), False,
    "the units of the four tensors", ("d2tau",), default=False, on_charts=False,
    returns=("d2tau_dqdq", "d2tau_dvdv", "dtau_dqdv", "dtau_dadq")))
# ... and of the forward dynamics, composed from them (no derivation of their own): with
# x = (q, qd, tau) and a = qdd(x), M d2a/dx_j dx_k = -(d2tau/dx_j dx_k + dM/dx_j da/dx_k +
# dM/dx_k da/dx_j) at qdd = a (docs/derivatives.md).
_FORWARD_SECOND_FROM = (MASS.function, INVERSE.function, FORWARD.function,
                        FORWARD_DERIVATIVES.function, SECOND_DERIVATIVES.function)
_FORWARD_SECOND_BACKENDS = ("numpy", "casadi", "c")
FORWARD_SECOND = _listed(Output(
    "forward_dynamics_second_derivatives", None, "d2qdd/dx2 of qdd(q, qd, tau), x = (q, qd, "
    "tau) stacked (3 nv): T[i, j, k] = d2qdd_i/dx_j dx_k returned as (nv, 9 nv*nv), entry "
    "[i, j*3nv + k]: reshape(nv, 3 nv, 3 nv) gives T.", ("q", "qd", "tau"), False,
    "1/s^2 per unit of x_j and x_k", ("M", "tau", "dqdd", "d2tau"),
    composed_from=_FORWARD_SECOND_FROM, default=False, on_charts=False,
    backends=_FORWARD_SECOND_BACKENDS))
FORWARD_HESSIAN = _listed(Output(
    "forward_dynamics_hessian", None, "Hessian (3 nv, 3 nv) of lam^T qdd(q, qd, tau) over x = "
    "(q, qd, tau), for the multipliers lam (nv,) (an optimizer's Lagrangian term), without "
    "the tensor.", ("q", "qd", "tau"), False, "1/s^2 per unit of x_j and x_k, times lam's",
    ("M", "tau", "dqdd", "d2tau"), composed_from=_FORWARD_SECOND_FROM, default=False,
    on_charts=False, backends=_FORWARD_SECOND_BACKENDS))

CONSTRAINED_PARTIALS = _listed(Output(
    "constrained_dynamics_partials", "dKKT", "[[dr/dq, dr/dqd], [da/dq, da/dqd]] (nv + m, 2 nv) "
    "of r = tau_c(q, qd, qdd, F_c) and the contact accelerations a = J_c qdd + J_c-dot qd.",
    ("q", "qd", "qdd", "F_c"), False, "mixed", ("dKKT",), default=False, constants=_CONTACT_NAMES))
CONSTRAINED_DERIVATIVES = _listed(Output(
    "constrained_forward_dynamics_derivatives", None, "d(qdd, F_c)/d(q, qd, tau) of "
    "constrained_forward_dynamics: K^-1 (-dKKT, [1; 0]), K its KKT matrix.", ("q", "qd", "tau"),
    False, "those of the forward dynamics derivatives; N per unit", ("M", "tau", "J_c", "dJqd_c",
    "dKKT"), composed_from=(*CONSTRAINED_FORWARD.composed_from, CONSTRAINED_FORWARD.function,
    CONSTRAINED_PARTIALS.function), default=False, constants=_CONTACT_NAMES,
    backends=("numpy", "fast", "casadi", "c", "jax", "torch")))

# --- issue 27: task-space quantities, composed from M, J_f, J_f-dot qd and tau (templates) --
#: The backends whose templates compose the task-space functions.
_TASK_BACKENDS = ("numpy", "fast", "jax", "torch")
_TASK_NOTE = ("Per frame of FRAME_NAMES, from its world-aligned Jacobian J at the frame origin "
              "(linear=True: its 3 linear rows)")
OPERATIONAL_SPACE_INERTIA = _listed(Output(
    "operational_space_inertia", None, "Operational-space inertia Lambda = (J M^-1 J^T + "
    "damping 1)^-1. " + _TASK_NOTE + ": (nf, 6, 6) or (nf, 3, 3).", ("q",), False,
    "kg (linear block), kg m (mixed), kg m^2 (angular block)", (MASS.symbol, "J_f"),
    composed_from=(MASS.function, FRAME_JACOBIANS.function), default=False,
    constants=_FRAME_NAMES, backends=_TASK_BACKENDS))
OPERATIONAL_SPACE_BIAS = _listed(Output(
    "operational_space_bias", None, "(mu, p) of the operational-space equations F = Lambda "
    "xdd + mu + p: mu = Lambda J M^-1 C qd - Lambda Jdot qd, p = Lambda J M^-1 g. " + _TASK_NOTE
    + ": (nf, 6) each, or (nf, 3).", ("q", "qd"), False, "N (linear rows), N m (angular rows)",
    (MASS.symbol, INVERSE.symbol, "J_f", "dJqd_f"),
    composed_from=(MASS.function, INVERSE.function, FRAME_JACOBIANS.function,
                   FRAME_JACOBIANS_DOT_QD.function), default=False, constants=_FRAME_NAMES,
    backends=_TASK_BACKENDS))
DYNAMICALLY_CONSISTENT_INVERSE = _listed(Output(
    "dynamically_consistent_inverse", None, "Dynamically consistent inverse Jbar = M^-1 J^T "
    "Lambda (J Jbar = 1 at damping 0). " + _TASK_NOTE + ": (nf, n, 6) or (nf, n, 3).", ("q",),
    False, "rad/m or 1 (linear columns), rad or m (angular columns)", (MASS.symbol, "J_f"),
    composed_from=(MASS.function, FRAME_JACOBIANS.function), default=False,
    constants=_FRAME_NAMES, backends=_TASK_BACKENDS))
TASK_SPACE = (OPERATIONAL_SPACE_INERTIA, OPERATIONAL_SPACE_BIAS, DYNAMICALLY_CONSISTENT_INVERSE)

# Issue 41: the passive forces of MuJoCo models (joint springs, drive damping, fixed tendons:
# eomgen.symbolic.passive, docs/formats.md), exported when asked for.
PASSIVE = _listed(Output(
    "passive_forces", "tau_p", "Passive joint forces -k (q - q_ref) - d qd + J_t^T f_t of the "
    "joint springs, the drives' viscous damping, the fixed tendons and gravity compensation "
    "(MuJoCo's qfrc_passive), "
    "added to tau: M qdd + C qd + g = tau + tau_p.", ("q", "qd"), True, _REVOLUTE_EFFORT,
    ("tau_p",), default=False))
# --- issue 41: MuJoCo's actuators on joints and fixed tendons (eomgen.symbolic.controls,
# docs/formats.md): the joint forces of the controls and the forward dynamics they drive.
_ACTUATOR_NAMES = ("ACTUATOR_NAMES",)
ACTUATOR_FORCES = _listed(Output(
    "actuator_forces", "tau_act", "Joint forces of the actuators sum gear clamp(gain(q, qd) "
    "clamp(ctrl) + bias(q, qd)) (MuJoCo's qfrc_actuator).", ("q", "qd", "ctrl"), True,
    _REVOLUTE_EFFORT, ("tau_act",), default=False, constants=_ACTUATOR_NAMES))
FORWARD_CTRL = _listed(Output(
    "forward_dynamics_ctrl", "qdd_ctrl", "Joint accelerations qdd = (M(q) + diag(a))^-1 "
    "(actuator_forces + passive_forces - C(q, qd) qd - g(q)) by the Articulated-Body "
    "Algorithm (MuJoCo's qacc_smooth).", ("q", "qd", "ctrl"), True,
    "rad/s^2 (revolute), m/s^2 (prismatic)", ("qdd_ctrl",), default=False,
    constants=_ACTUATOR_NAMES))
FORWARD_CTRL_DERIVATIVE = _listed(Output(
    "forward_dynamics_ctrl_derivative_ctrl", "dqdd_dctrl", "dqdd/dctrl (nv, nu) of "
    "forward_dynamics_ctrl: (M + diag(a))^-1 dtau_act/dctrl (zero where a clamp holds).",
    ("q", "qd", "ctrl"), False, "rad/s^2 (revolute rows), m/s^2 (prismatic) per unit of ctrl",
    ("dqdd_dctrl",), default=False, constants=_ACTUATOR_NAMES))
FORWARD_CTRL_DQ = _listed(Output(
    "forward_dynamics_ctrl_derivative_q", "dqdd_ctrl_dq", "dqdd/dq (nv, nv) of "
    "forward_dynamics_ctrl: -(M + diag(a))^-1 (dtau/dq - d(actuator_forces + "
    "passive_forces)/dq), dtau/dq of Newton-Euler at qdd held fixed.", ("q", "qd", "ctrl"),
    False, "1/s^2", ("dqdd_ctrl_dq",), default=False, constants=_ACTUATOR_NAMES))
FORWARD_CTRL_DQD = _listed(Output(
    "forward_dynamics_ctrl_derivative_qd", "dqdd_ctrl_dqd", "dqdd/dqd (nv, nv) of "
    "forward_dynamics_ctrl (the servos' and the passive forces' damping included).",
    ("q", "qd", "ctrl"), False, "1/s", ("dqdd_ctrl_dqd",), default=False,
    constants=_ACTUATOR_NAMES))
FORWARD_CTRL_DERIVATIVES = _listed(Output(
    "forward_dynamics_ctrl_derivatives", "dqdd_ctrl_dx", "(dqdd/dq, dqdd/dqd) of "
    "forward_dynamics_ctrl in one call.", ("q", "qd", "ctrl"), False,
    "the units of forward_dynamics_ctrl_derivative_q and _qd", ("dqdd_ctrl_dx",),
    default=False, constants=_ACTUATOR_NAMES, returns=("dqdd_ctrl_dq", "dqdd_ctrl_dqd")))
FORWARD_ACT = _listed(Output(
    "forward_dynamics_act", "xd_act", "(qdd, act_dot) stacked (nv + na,) of a model whose "
    "actuators have activation dynamics (integrator: act_dot = ctrl; filter, filterexact: "
    "(ctrl - act) / timeconst; a DC motor's current), their forces gain act + bias (MuJoCo's "
    "qacc_smooth, act_dot).",
    ("q", "qd", "ctrl", "act"), True, "rad/s^2 or m/s^2 (qdd), activation units/s (act_dot)",
    ("xd_act",), default=False, constants=("ACTUATOR_NAMES", "ACTIVATION_NAMES")))
# the derivatives of forward_dynamics_act, for MPC on the state x = (q, qd, act), u = ctrl
# (eomgen.symbolic.controls; dq along the tangent of a quaternion joint)
_ACTIVATION_NAMES = ("ACTUATOR_NAMES", "ACTIVATION_NAMES")
FORWARD_ACT_DERIVATIVES = _listed(Output(
    "forward_dynamics_act_derivatives", "dxd_act", "d(qdd, act_dot)/d(q, qd, ctrl, act) "
    "(nv + na, 2 nv + nu + na) of forward_dynamics_act: rows qdd then act_dot, columns "
    "dq (tangent), dqd, dctrl, dact side by side (zero where a clamp holds).",
    ("q", "qd", "ctrl", "act"), False, "those of forward_dynamics_act per unit of each column",
    ("dxd_act",), default=False, constants=_ACTIVATION_NAMES))
STATE_MATRIX_ACT = _listed(Output(
    "state_matrix_act", "A_act", "A = df/dx (2 nv + na, 2 nv + na) of xdot = f(x, ctrl), x = "
    "(q, qd, act): [[T, I, 0], [dqdd/dq, dqdd/dqd, dqdd/dact], [dact_dot/dq, dact_dot/dqd, "
    "dact_dot/dact]], T as in state_matrix.", ("q", "qd", "ctrl", "act"), False,
    "1, 1/s, 1/s^2 and those of forward_dynamics_act_derivatives", ("A_act",), default=False,
    constants=_ACTIVATION_NAMES))
INPUT_MATRIX_ACT = _listed(Output(
    "input_matrix_act", "B_act", "B = df/dctrl (2 nv + na, nu) of xdot = f(x, ctrl), x = "
    "(q, qd, act): [[0], [dqdd/dctrl], [dact_dot/dctrl]].", ("q", "qd", "ctrl", "act"), False,
    "those of forward_dynamics_act per unit of ctrl", ("B_act",), default=False,
    constants=_ACTIVATION_NAMES))

#: Every output, in module order (:mod:`eomgen.outputs` indexes them).
CATALOGUE: tuple[Output, ...] = tuple(_ENTRIES)
