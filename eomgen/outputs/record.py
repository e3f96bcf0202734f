"""What an output of a generated module is (:class:`Output`) and the inputs its functions take
(:data:`INPUTS`, :data:`INPUT_SIZES`): the record type of :mod:`eomgen.outputs.catalogue`,
which holds the entries.

Data only, as the catalogue: it imports nothing of eomgen (docs/architecture.md, layer 0).
"""

from __future__ import annotations

from dataclasses import dataclass

#: The vector inputs a generated function may take, each of length n (the joints, in
#: ``JOINT_NAMES`` order) unless :data:`INPUT_SIZES` gives another length, with their
#: docstring line. Their symbols are ``<name>1 … <name>n``
#: (:attr:`eomgen.symbolic.derivation.Derivation.inputs`); adding an input is one line here.
INPUTS: dict[str, str] = {
    "q": "joint positions [rad or m]",
    "qd": "joint velocities [rad/s or m/s]",
    "qdd": "joint accelerations [rad/s^2 or m/s^2]",
    "tau": "joint efforts [N m or N]",
    "theta_m": "motor angles of the flexible joints, link side of the gear [rad] (entries of "
             "rigid joints are ignored)",
    "thetad_m": "motor velocities of the flexible joints, link side of the gear [rad/s] "
              "(entries of rigid joints are ignored)",
    "qddd": "third time derivatives of the joint positions (jerk) [rad/s^3 or m/s^3]",
    "qdddd": "fourth time derivatives of the joint positions (snap) [rad/s^4 or m/s^4]",
    "F_c": "contact forces on the robot, rows CONTACT_ROWS (point contacts: force [N] in world "
           "axes; surface contacts: force [N] and moment [N m] in the contact frame's axes; "
           "then the loop forces on each loop's frame b, in its rows' axes)",
    "qd_r": "reference joint velocities of the Slotine-Li controller [rad/s or m/s]",
    "qdd_r": "reference joint accelerations of the Slotine-Li controller [rad/s^2 or m/s^2]",
    "ctrl": "controls of the actuators, in ACTUATOR_NAMES order (MuJoCo's ctrl)",
    "act": "activations of the actuators with activation dynamics, in ACTIVATION_NAMES order "
           "(MuJoCo's act)",
}

#: The inputs whose length is not the number of joints, with what their length is; the function
#: giving it for a model is registered where it is computed
#: (:func:`eomgen.symbolic.builders.sizes`, :func:`~eomgen.symbolic.builders.input_size`).
INPUT_SIZES: dict[str, str] = {
    "q": "NQ, the configuration size (NV + 1 per quaternion joint)",
    "F_c": "m, the constraint rows: the contacts' (CONTACT_ROWS), then the loops'",
    "ctrl": "nu, the model's controls (ACTUATOR_NAMES)",
    "act": "na, the controls with activation dynamics (ACTIVATION_NAMES)",
}


@dataclass(frozen=True)
class Output:
    """One function of a generated module.

    Attributes
    ----------
    function:
        Its name in the generated module (a Python and C identifier).
    symbol:
        The derived quantity it returns (``"M"``), the key of :attr:`Dynamics.outputs
        <eomgen.dynamics.Dynamics.outputs>` and a short name callers may use; ``None`` for a
        composed function.
    summary:
        The first line of its docstring.
    inputs:
        Names of its vector inputs, in call order (``"q"``, ``"qd"``, ``"qdd"``, ``"tau"``).
    is_vector:
        Whether it returns an (n,) vector rather than an (n, n) matrix.
    units:
        Units of the result's entries.
    needs:
        Symbols of the derived outputs it needs (its own symbol for a printed output).
    composed_from:
        Functions a composed output is built from (generated along with it); empty otherwise.
    default:
        Whether a generated module exports it when the caller names no outputs.
    constants:
        The name tuples a module exporting this output also exports (e.g. ``PARAMETER_NAMES``,
        the columns of the regressor), in order; their values come from the function registered
        for exactly these names (:func:`eomgen.symbolic.builders.provides`).
    backends:
        For a composed output, the backends whose templates compose it (``None``: every one);
        the others leave it out of their modules.
    on_charts:
        Whether it is derived for a model whose configuration is not its coordinates (nq > nv:
        a joint kind with a chart, :class:`~eomgen.model.joints.ChartKind`, such as a
        quaternion free flyer or a ball joint); :func:`eomgen.derive` refuses the others.
    returns:
        For a function returning several results from one program (sharing its intermediates):
        the symbols of the printed outputs it returns, in order. Its own ``symbol`` is then the
        side-by-side matrix of those results (each n rows; a vector is one column), which the
        module splits into the tuple it returns. Empty for a function of one result.
    width:
        The columns of a matrix result in units of n (2 for the 2n × 2n state matrix of
        ``linearize``), for :func:`eomgen.outputs.splits`.
    tensor:
        Whether the result is a 3-index tensor ``T[i, j, k]`` (n, nv, nv), returned as the
        matrix (n, nv·nv) with entry ``[i, j·nv + k]`` (``reshape(n, nv, nv)`` in C order).
    """

    function: str
    symbol: str | None
    summary: str
    inputs: tuple[str, ...]
    is_vector: bool
    units: str
    needs: tuple[str, ...]
    composed_from: tuple[str, ...] = ()
    default: bool = True
    constants: tuple[str, ...] = ()
    backends: tuple[str, ...] | None = None
    on_charts: bool = True
    returns: tuple[str, ...] = ()
    width: int = 1
    tensor: bool = False

    @property
    def composed(self) -> bool:
        """Whether backends compose it from other functions instead of printing a program."""
        return bool(self.composed_from)

    def shape(self, n: int) -> tuple[int, ...]:
        """Its result's shape for ``n`` joints, for the outputs whose rows and columns are the
        joints (the printed shape of any output is that of the matrix its builder returns)."""
        return (n,) if self.is_vector else (n, n * n) if self.tensor else (n, n)


__all__ = ["INPUTS", "INPUT_SIZES", "Output"]
