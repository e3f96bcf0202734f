"""MuJoCo's actuators as eomgen reads them (:mod:`eomgen.parsers.mjcf`): the
:class:`~eomgen.model.Control` of each actuator on a hinge or slide joint or a fixed tendon
whose gain, bias and dynamics eomgen models (affine servos, activation filters and integrators
with or without ``actearly``, DC motors on their voltage, PIDs on their position), and one
notice per kind of the others.
"""

from __future__ import annotations

import numpy as np

from ...model import Control, Notice, make_control
from .tree import (HINGE, SLIDE, actuator_count, disabled, element_name, is_fixed,
                   joint_names, not_modelled, tendon_joints)

#: MuJoCo's transmission, dynamics, gain and bias types of a plain motor (``mjTRN_JOINT``,
#: ``mjDYN_NONE``, ``mjGAIN_FIXED``, ``mjBIAS_NONE``) and of ``mjTRN_JOINTINPARENT``.
_TRN_JOINT, _TRN_JOINT_IN_PARENT, TRN_TENDON = 0, 1, 3
_TRN_NAMES = {2: "slider-crank", 3: "tendon", 4: "site", 5: "body"}
_DYN_NAMES = {1: "integrator", 2: "filter", 3: "filterexact", 4: "muscle", 5: "DC motor",
              6: "PID"}
#: The activation dynamics eomgen reads (:attr:`eomgen.model.Control.dynamics`).
_DYN_READ = {1: "integrator", 2: "filter", 3: "filterexact"}
_GAIN_FIXED, _GAIN_AFFINE, _GAIN_MUSCLE = 0, 1, 2
_BIAS_NONE, _BIAS_AFFINE = 0, 1
#: A DC motor's dynamics, gain and bias types (``mjDYN_DCMOTOR``, ``mjGAIN_DCMOTOR``,
#: ``mjBIAS_DCMOTOR``) and its plain voltage input (``mjINPUT_VOLTAGE``, ``actuator_ctrlspec``).
_DYN_DCMOTOR, _GAIN_DCMOTOR, _BIAS_DCMOTOR, _INPUT_VOLTAGE = 5, 3, 3, 8
#: A PID's dynamics and gain types (``mjDYN_PID``, ``mjGAIN_PID``) and its position input.
_DYN_PID, _GAIN_PID, _INPUT_POS = 6, 5, 1
#: MuJoCo's ``mjMINVAL``: the smallest time constant and resistance it divides by.
_MINVAL = 1e-15


def motors(m) -> tuple[tuple[str, str, float], ...]:
    """``(actuator, joint, gear)`` of each plain motor on a hinge or slide joint: MuJoCo applies
    the joint torque ``gear · ctrl`` [N m or N] (``gear`` includes a ``<general>``'s gain)."""
    jnames = joint_names(m)
    return tuple((element_name(m, "actuator", i), jnames[int(m.actuator_trnid[i, 0])],
                  float(m.actuator_gear[i, 0] * m.actuator_gainprm[i, 0]))
                 for i in range(actuator_count(m)) if is_motor(m, i))


def is_motor(m, i: int) -> bool:
    """Whether actuator ``i`` is a plain motor (fixed gain, no bias) on a joint eomgen reads."""
    return (is_control(m, i) and int(m.actuator_trntype[i]) != TRN_TENDON
            and int(m.actuator_dyntype[i]) == 0
            and int(m.actuator_gaintype[i]) == _GAIN_FIXED
            and int(m.actuator_biastype[i]) == _BIAS_NONE)


def is_control(m, i: int) -> bool:
    """Whether actuator ``i`` is one eomgen reads as a :class:`~eomgen.model.Control`: a joint
    transmission on a hinge or slide joint or a transmission on a fixed tendon, no activation
    dynamics or an integrator or filter one (:func:`_dynamics_read`), a fixed or affine gain and
    no or an affine bias (``<motor>``, ``<position>``, ``<velocity>``, ``<intvelocity>``,
    ``<general>`` of those types), or a ``<dcmotor>`` on its voltage input whose every feature
    eomgen models (:func:`dcmotor_left_out`)."""
    trn = int(m.actuator_trntype[i])
    if trn in (_TRN_JOINT, _TRN_JOINT_IN_PARENT):
        if int(m.jnt_type[int(m.actuator_trnid[i, 0])]) not in (HINGE, SLIDE):
            return False
    elif trn != TRN_TENDON or not is_fixed(m, int(m.actuator_trnid[i, 0])):
        return False
    if int(m.actuator_dyntype[i]) == _DYN_DCMOTOR:
        return (int(m.actuator_gaintype[i]) == _GAIN_DCMOTOR
                and int(m.actuator_biastype[i]) == _BIAS_DCMOTOR
                and dcmotor_left_out(m, i) is None)
    if int(m.actuator_gaintype[i]) == _GAIN_PID:
        return pid_left_out(m, i) is None
    return (int(getattr(m, "actuator_ctrlnum", np.ones(actuator_count(m)))[i]) == 1
            and _dynamics_read(m, i)
            and int(m.actuator_gaintype[i]) in (_GAIN_FIXED, _GAIN_AFFINE)
            and int(m.actuator_biastype[i]) in (_BIAS_NONE, _BIAS_AFFINE))


def _early(m, i: int) -> bool:
    """Whether actuator ``i`` has ``actearly`` (its force uses the next step's activation)."""
    return bool(getattr(m, "actuator_actearly", np.zeros(actuator_count(m)))[i])


def _dynamics_read(m, i: int) -> bool:
    """Whether eomgen reads actuator ``i``'s activation dynamics: none, or an integrator or a
    filter of one activation (its force at the activation, or with ``actearly`` one step
    ahead)."""
    dyntype = int(m.actuator_dyntype[i])
    return dyntype == 0 or (dyntype in _DYN_READ and int(m.actuator_actnum[i]) == 1)


def dcmotor_left_out(m, i: int) -> str | None:
    """The first feature of DC motor ``i`` eomgen does not model, as its MJCF attribute with
    what it adds; None when every one is modelled (the voltage input, ``resistance``,
    ``motorconst``, ``nominal``, ``inductance``, ``saturation``, ``cogging``)."""
    dyn, gain = m.actuator_dynprm[i], m.actuator_gainprm[i]
    if int(m.actuator_ctrlspec[i]) != _INPUT_VOLTAGE or int(m.actuator_ctrlnum[i]) != 1:
        return "input (an on-board controller's setpoints, or none)"
    if any(float(x) for x in gain[4:8]) or float(dyn[7]) > 0 or float(dyn[8]) > 0:
        return "controller (PID gains, slew, integral and voltage limits)"
    if float(dyn[2]) > 0:
        return "thermal (a winding temperature state)"
    if float(dyn[5]) > 0:
        return "lugre (a bristle state)"
    return None


def pid_left_out(m, i: int) -> str | None:
    """The first feature of PID ``i`` eomgen does not model, as its MJCF attribute; None when
    it is a PID on its position input alone (``input="pos"``) with no ``slewmax`` and, with
    an integral gain ``ki``, no ``imax``."""
    dyn = m.actuator_dynprm[i]
    if int(m.actuator_biastype[i]) != _BIAS_AFFINE or int(m.actuator_dyntype[i]) not in (
            0, _DYN_PID):
        return "gain and bias types"
    if int(m.actuator_ctrlspec[i]) != _INPUT_POS or int(m.actuator_ctrlnum[i]) != 1:
        return "input (vel or ff inputs: several controls per actuator)"
    if float(dyn[1]) > 0:
        return "slewmax (a setpoint state)"
    if float(m.actuator_gainprm[i, 0]) > 0 and float(dyn[0]) > 0:
        return "imax (the integral's anti-windup)"
    return None


def _early_step(m, i: int) -> float | None:
    """``α`` of actuator ``i``'s ``actearly`` (:attr:`eomgen.model.Control.early`): its force
    at ``act + α act_dot``, MuJoCo's ``mj_nextActivation`` one time step ``h`` ahead: ``h``
    (Euler) for an integrator or a filter, ``T (1 − exp(−h / T))`` for ``filterexact`` and a DC
    motor's current; None without ``actearly`` or activation."""
    dyntype = int(m.actuator_dyntype[i])
    if not _early(m, i) or not int(m.actuator_actnum[i]):
        return None
    h = float(m.opt.timestep)
    if dyntype in (3, _DYN_DCMOTOR):
        T = max(_MINVAL, float(m.actuator_dynprm[i, 0]))
        return T * (1 - float(np.exp(-h / T)))
    return h


def controls(m) -> tuple[Control, ...]:
    """The :class:`~eomgen.model.Control` of each actuator :func:`is_control` reads, in
    MuJoCo's actuator order: ``gear`` its first component, the gain and bias the first three
    of ``gainprm``/``biasprm`` (a fixed gain keeps only the first, no bias is zero), the
    control clamped to ``ctrlrange`` when ``ctrllimited`` (and clamping is not disabled), the
    force to ``forcerange`` when ``forcelimited``; on a fixed tendon, the tendon's name and
    coefficients (``wrap_prm``: MuJoCo's moment is ``gear`` times them)."""
    jnames = joint_names(m)
    clamp_ctrl = not disabled(m, "CLAMPCTRL")
    out = []
    for i in (i for i in range(actuator_count(m)) if is_control(m, i)):
        gain = [float(x) for x in m.actuator_gainprm[i, :3]]
        if int(m.actuator_gaintype[i]) == _GAIN_FIXED:
            gain[1:] = [0.0, 0.0]
        bias = ([float(x) for x in m.actuator_biasprm[i, :3]]
                if int(m.actuator_biastype[i]) == _BIAS_AFFINE else [0.0, 0.0, 0.0])
        ctrl = (m.actuator_ctrlrange[i].tolist()
                if clamp_ctrl and bool(m.actuator_ctrllimited[i]) else None)
        force = m.actuator_forcerange[i].tolist() if bool(m.actuator_forcelimited[i]) else None
        target = int(m.actuator_trnid[i, 0])
        if int(m.actuator_trntype[i]) == TRN_TENDON:
            where = {"joint": None, "tendon": element_name(m, "tendon", target),
                     "coefficients": tuple(
                (jnames[j], c) for j, c in tendon_joints(m, target))}
        else:
            where = {"joint": jnames[target]}
        dyntype = int(m.actuator_dyntype[i])
        early = _early_step(m, i)
        actrange = (m.actuator_actrange[i].tolist() if early is not None
                    and dyntype != _DYN_DCMOTOR and bool(m.actuator_actlimited[i]) else None)
        motor: dict = {"dynamics": _DYN_READ.get(dyntype)}
        if dyntype == _DYN_DCMOTOR:
            motor, gain, bias = _dcmotor(m, i)
        elif int(m.actuator_gaintype[i]) == _GAIN_PID:  # kp on ctrl, ki on the integral
            gain = [-float(m.actuator_biasprm[i, 1]), 0.0, 0.0]
            ki = float(m.actuator_gainprm[i, 0])
            if ki > 0:
                motor = {"dynamics": "pid", "integral": ki}
        timeconst = float(m.actuator_dynprm[i, 0]) if motor.get("dynamics") not in (
            None, "integrator", "pid") else 1
        out.append(make_control(element_name(m, "actuator", i), gear=float(m.actuator_gear[i, 0]),
                                gain=gain, bias=bias, ctrlrange=ctrl, forcerange=force,
                                timeconst=timeconst, early=early, actrange=actrange, **motor,
                                **where))
    return tuple(out)


def _dcmotor(m, i: int) -> tuple[dict, list, list]:
    """``(fields, gain, bias)`` of DC motor ``i`` as a :class:`~eomgen.model.Control` (its
    module docstring): with a current state (``inductance``, ``dynprm[0] = T > 0``) the
    dynamics ``"dcmotor"``, ``motor = (R, K)`` (``gainprm[0:2]``), the current rate limit
    ``dynprm[1]`` and the force ``K · act``; without, the affine force ``K/R (V − K v)``.
    The cogging torque ``biasprm[0:3]`` either way."""
    R, K = (float(x) for x in m.actuator_gainprm[i, :2])
    dyn, cog = m.actuator_dynprm[i], [float(x) for x in m.actuator_biasprm[i, :3]]
    fields: dict = {"dynamics": None, "cogging": cog if cog[0] else None}
    if float(dyn[0]) > 0:
        fields.update(dynamics="dcmotor", motor=(R, K),
                      rate_limit=float(dyn[1]) if float(dyn[1]) > 0 else None)
        return fields, [K, 0.0, 0.0], [0.0, 0.0, 0.0]
    gain = K / max(_MINVAL, R)
    return fields, [gain, 0.0, 0.0], [0.0, 0.0, -gain * K]


def _actuator_kind(m, i: int) -> tuple[str, str]:
    """What actuator ``i`` (one :func:`is_control` does not read) is: ``(one, several)``."""
    trn = int(m.actuator_trntype[i])
    if trn == TRN_TENDON and not is_fixed(m, int(m.actuator_trnid[i, 0])):
        return "an actuator on a spatial tendon is", "actuators on spatial tendons are"
    if trn in _TRN_NAMES and trn != TRN_TENDON:
        kind = f"on a {_TRN_NAMES[trn]}"
        return f"an actuator {kind} is", f"actuators {kind} are"
    if int(m.actuator_gaintype[i]) == _GAIN_MUSCLE or int(m.actuator_dyntype[i]) == 4:
        return "a muscle is", "muscles are"
    if trn != TRN_TENDON and int(m.jnt_type[int(m.actuator_trnid[i, 0])]) not in (HINGE, SLIDE):
        return "an actuator on a free or ball joint is", "actuators on free or ball joints are"
    if int(m.actuator_dyntype[i]) == _DYN_DCMOTOR and dcmotor_left_out(m, i):
        feature = dcmotor_left_out(m, i)
        return (f"a DC motor's {feature} is", f"DC motors' {feature} are")
    if int(m.actuator_gaintype[i]) == _GAIN_PID:
        feature = pid_left_out(m, i)
        return (f"a PID's {feature} is", f"PIDs' {feature} are")
    if int(m.actuator_dyntype[i]):
        dynamics = _DYN_NAMES.get(int(m.actuator_dyntype[i]), "its own")
        return (f"an actuator with {dynamics} dynamics (activation) is",
                f"actuators with {dynamics} dynamics (activation) are")
    return ("an actuator with a user-defined gain or bias is",
            "actuators with a user-defined gain or bias are")


def actuator_notices(m, source: str) -> list[Notice]:
    """One notice per kind of actuator eomgen does not read (:func:`_actuator_kind`), with
    their count and first three names."""
    jnames = joint_names(m)
    kinds: dict[tuple[str, str], list[tuple[str, tuple[str, ...]]]] = {}
    for i in range(actuator_count(m)):
        if is_control(m, i):
            continue
        on_joint = int(m.actuator_trntype[i]) in (_TRN_JOINT, _TRN_JOINT_IN_PARENT)
        joints = (jnames[int(m.actuator_trnid[i, 0])],) if on_joint else ()
        kinds.setdefault(_actuator_kind(m, i), []).append((element_name(m, "actuator", i), joints))
    notices = []
    for kind, found in kinds.items():
        names = [f"'{name}'" for name, _ in found]
        shown = ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")
        joints = tuple(j for _, js in found for j in js)
        every_on_joint = all(js for _, js in found)
        notices.append(not_modelled(source, f"actuator {shown}" if len(found) == 1 else
                               f"{len(found)} actuators {shown}",
                               f"{kind[0] if len(found) == 1 else kind[1]} not modelled",
                               "left out of ctrl (docs/formats.md, "
                               "MJCF actuators)", joints=joints if every_on_joint else ()))
    return notices


__all__ = ["TRN_TENDON", "actuator_notices", "controls", "dcmotor_left_out", "is_control",
           "is_motor", "motors", "pid_left_out"]
