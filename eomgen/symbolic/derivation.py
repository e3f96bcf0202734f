"""The derivation: what every symbolic algorithm works on, made in one place.

A :class:`Derivation` holds a model, its body tree (fixed links merged, :mod:`eomgen.model.bodies`),
the symbols of each input vector in ``JOINT_NAMES`` order and the program builder the
algorithms define their intermediates in. :func:`new_derivation` is the only function that
builds one; :func:`eomgen.derive`, the algorithm entry points (CRBA, ABA, Newton–Euler, the
regressor, frames, the combined programs) and the output builders (registered in
:mod:`eomgen.symbolic.builders`, each found by its symbol) all start from it, so that the symbols, the reserved names and the sizes of the inputs are decided
once.

Symbols: ``q1 … qn`` [rad or m] (``n`` = NQ, the configuration size: seven entries more
than the joints for a free flyer or ball joints, :mod:`eomgen.model.quaternion`), ``qd1 … qdn`` [rad/s or m/s], ``qdd1 … qddn`` [rad/s² or
m/s²], ``tau1 … taun`` [N m or N]; an input of :data:`eomgen.outputs.INPUTS` is
``<name>1 … <name>k`` with ``k`` its own size (:func:`eomgen.symbolic.builders.input_size`: the
number of joints unless the catalogue says otherwise, e.g. the contact rows of ``F_c``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Iterable

import sympy as sp

from ..model.bodies import BodyTree, body_tree
from ..model import RobotModel, configuration_size, float_constants
from ..errors import UnsupportedError
from ..outputs import BY_SYMBOL, INPUTS
from .builders import builder_of, input_size, sizes
from .couplings import coupled_inputs, project, refused
from .charts import chart_accelerations, coordinates, placements
from .program import Program, ProgramBuilder

# ``q`` is NQ long: the configuration, an entry more than the velocity per quaternion joint.
sizes("q")(configuration_size)


def vector_symbols(prefix: str, n: int) -> tuple[sp.Symbol, ...]:
    """Symbols ``<prefix>1 … <prefix>n`` (real): the entries of an input vector."""
    return tuple(sp.Symbol(f"{prefix}{k + 1}", real=True) for k in range(n))


def joint_symbols(n: int) -> tuple[tuple[sp.Symbol, ...], tuple[sp.Symbol, ...], tuple[sp.Symbol, ...]]:
    """Symbols ``q1…qn``, ``qd1…qdn``, ``qdd1…qddn`` (real)."""
    return vector_symbols("q", n), vector_symbols("qd", n), vector_symbols("qdd", n)


@dataclass(frozen=True)
class Derivation:
    """What an algorithm or an output's builder (:func:`~eomgen.symbolic.builders.builds`)
    works with: the model, its body tree (fixed links merged), the symbols of every input vector it
    was made with, in ``JOINT_NAMES`` order (``inputs["q"]`` is ``q1 … qn``; also as the
    attributes ``q``, ``qd``, ``qdd``, ``tau``), and the program builder to define
    intermediates in. ``shared`` lets builders keep what another builder may reuse (keyed by
    the builder's own module name). Made by :func:`new_derivation` only."""

    model: RobotModel
    tree: BodyTree
    inputs: dict[str, tuple[sp.Symbol, ...]]
    builder: ProgramBuilder
    shared: dict = field(default_factory=dict)
    #: The joint coordinates the algorithms index by ``RigidBody.q_index`` (NV entries), when
    #: they are not ``inputs["q"]``: the virtual joints of a free flyer or a ball joint are
    #: held at zero, the pose from its quaternion placed above them
    #: (:mod:`eomgen.symbolic.charts`).
    coordinates: tuple | None = None
    #: For a model with coupled joints (:mod:`eomgen.symbolic.couplings`): ``T`` of
    #: ``q_full = T q + c`` and the full velocities ``T q̇``; :attr:`model` is then the
    #: whole tree (every movable joint a coordinate) and :meth:`program` projects each output
    #: to the independent coordinates.
    coupling: sp.Matrix | None = None
    velocities: tuple | None = None
    #: With coupled joints, the whole tree's configuration (NQ_full entries of
    #: :attr:`model`'s, a quaternion's block copied from ``q``, :attr:`configuration`).
    full_configuration: tuple | None = None

    @property
    def configuration(self) -> tuple:
        """The configuration of :attr:`model` (NQ entries, a quaternion joint's four among
        them): the ``q`` input, or with coupled joints the whole tree's."""
        return self.inputs["q"] if self.full_configuration is None else self.full_configuration

    @property
    def q(self) -> tuple:
        """The joint coordinates the algorithms use, one per velocity (NV): the ``q`` input
        itself unless the model has quaternion joints (:attr:`coordinates`)."""
        return self.inputs["q"] if self.coordinates is None else self.coordinates

    @property
    def qd(self) -> tuple:
        """The joint velocities the algorithms use (NV): the ``qd`` input, or with coupled
        joints the full velocities ``T q̇`` (:attr:`coupling`)."""
        return self.inputs["qd"] if self.velocities is None else self.velocities

    @property
    def qdd(self) -> tuple:
        """The accelerations the algorithms take: the ``qdd`` input, with quaternion joints
        turned into the chart's (:func:`eomgen.symbolic.charts.chart_accelerations`)."""
        return self.accelerations(self.inputs["qdd"])

    def accelerations(self, qdd) -> tuple:
        """The accelerations an algorithm must be given for the true accelerations ``qdd``
        (with velocities ``qd``): ``qdd`` itself, or with quaternion joints the chart's; with coupled
        joints, independent accelerations (``len(qdd)`` the ``qdd`` input's) become the full
        ``T q̈``."""
        if self.coupling is not None and len(qdd) == self.coupling.cols:
            qdd = tuple(self.coupling * sp.Matrix(qdd))
        if self.model.nq == self.model.dof:  # no chart
            return tuple(qdd)
        return chart_accelerations(self.model, self.qd, qdd)

    def tangent(self, vector) -> tuple:
        """A velocity-like input vector (``qd_r``, ``qdd_r``) as the algorithms take it: itself,
        or with coupled joints the whole tree's ``T x``."""
        if self.coupling is None:
            return tuple(vector)
        return tuple(self.coupling * sp.Matrix(vector))

    @property
    def tau(self) -> tuple[sp.Symbol, ...]:
        return self.inputs["tau"]

    def size(self, name: str) -> int:
        """The length of input vector ``name`` (``size("q")`` is the number of joints)."""
        return len(self.inputs[name])

    @property
    def built(self) -> dict[str, sp.Matrix]:
        """The outputs built so far, by symbol (extra symbols such as ``P`` included)."""
        return self.shared.setdefault("outputs", {})

    def output(self, symbol: str) -> sp.Matrix:
        """The matrix of the registered output ``symbol``, built now if it was not yet (a
        builder that needs M calls ``derivation.output("M")``: M is built once per program)."""
        if symbol not in self.built:
            self.build({symbol})
        return self.built[symbol]

    def build(self, symbols) -> None:
        """Build the registered ``symbols`` not built yet, in registry order, each by the
        builder registered for it (:func:`eomgen.symbolic.builders.builder_of`); outputs sharing
        a builder are built in one call."""
        symbols = set(symbols)
        for symbol in BY_SYMBOL:
            if symbol not in symbols or symbol in self.built:
                continue
            builder = builder_of(symbol)
            wanted = {s for s in symbols - set(self.built) if builder_of(s) is builder}
            made = builder(self, wanted)
            self.built.update({k: v for k, v in made.items() if k not in self.built})

    def program(self, outputs: Iterable[tuple[str, sp.Matrix]]) -> Program:
        """The straight-line program of ``outputs`` (``(name, matrix)`` pairs, in order): the
        builder's intermediates, pruned to those the outputs need. With coupled joints each
        registered output is first projected to the independent coordinates
        (:func:`eomgen.symbolic.couplings.project`); another name is refused."""
        outputs = tuple(outputs)
        if self.coupling is not None:
            outputs = tuple((name, self._projected(name, matrix)) for name, matrix in outputs)
        return Program(tuple(self.builder.assignments), outputs).pruned([n for n, _ in outputs])

    def _projected(self, name: str, matrix: sp.Matrix) -> sp.Matrix:
        if refused([name]):
            raise UnsupportedError(self.model.source, f"output {name}", "not derived for a "
                                   "model with coupled joints (eomgen.symbolic.couplings)")
        return project(name, sp.Matrix(matrix), self.coupling)


def new_derivation(model: RobotModel, inputs: Iterable[str] | None = None) -> Derivation:
    """Start a derivation of ``model``: its body tree, the symbols of the input vectors
    ``inputs`` (names of :data:`eomgen.outputs.INPUTS`; all of them by default) and a program
    builder that never names an intermediate after an input or a parameter of the model.

    ``q``, ``qd`` and ``qdd`` are always made (every algorithm indexes joints by them); only
    the ``inputs`` asked for are reserved as names, so an algorithm that takes fewer inputs
    names its intermediates as before.

    Examples
    --------
    >>> import eomgen
    >>> d = new_derivation(eomgen.load(eomgen.example_path("planar_2link")), ("q", "qd"))
    >>> d.q, d.size("qd")
    ((q1, q2), 2)
    """
    names = tuple(INPUTS) if inputs is None else tuple(inputs)
    unknown = [name for name in names if name not in INPUTS]
    if unknown:
        raise ValueError(f"unknown inputs {unknown}; choose from {tuple(INPUTS)}")
    symbols = {name: vector_symbols(name, input_size(name, model)) for name in names}
    reserved = {s.name for v in symbols.values() for s in v} | {p.name for p in model.parameters}
    for name in ("q", "qd", "qdd"):
        symbols.setdefault(name, vector_symbols(name, input_size(name, model)))
    ordered = {name: symbols[name] for name in INPUTS if name in symbols}
    builder = ProgramBuilder(reserved)
    if model.couplings:  # the whole tree in full coordinates (eomgen.symbolic.couplings)
        full, T, q_full, qd_full = coupled_inputs(model, ordered["q"], ordered["qd"])
        tree, coords = _placed(full, q_full, builder)
        return Derivation(full, tree, ordered, builder, coordinates=coords, coupling=T,
                          velocities=qd_full, full_configuration=tuple(q_full))
    tree, coords = _placed(model, ordered["q"], builder)
    return Derivation(model, tree, ordered, builder,
                      coordinates=coords if model.nq > model.dof else None)


def _placed(model: RobotModel, q, builder: ProgramBuilder) -> tuple[BodyTree, tuple]:
    """The body tree of ``model`` with each quaternion joint's pose placed from ``q`` (NQ
    entries) before its chain, and the joint coordinates the algorithms index (NV). A model
    with floats is placed with its irrational constants as floats (:func:`~eomgen.model.
    float_constants`), so that they fold with the floats."""
    tree = body_tree(float_constants(model))
    if model.nq == model.dof:  # every configuration entry is a coordinate
        return tree, tuple(q)
    placed = placements(model, q, builder)
    tree = replace(tree, bodies=tuple(
        replace(body, placement=body.placement @ placed[body.q_index])
        if body.q_index in placed else body for body in tree.bodies))
    return tree, coordinates(model, q, model.dof)


__all__ = ["Derivation", "joint_symbols", "new_derivation", "vector_symbols"]
