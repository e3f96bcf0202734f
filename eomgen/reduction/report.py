"""The report of a reduction (:class:`ReductionReport`, with the model: :class:`Reduction`):
sizes before and after, what was locked, merged and dropped, derivation costs when measured
(:class:`DerivationCost`, measured by :mod:`eomgen.codegen.derivation_cost`), as data and as Markdown."""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

from ..common import reprs
from ..model import RobotModel
from .inertia import is_zero_inertial
from .planar import PlanarMotion


@dataclass(frozen=True)
class ModelSize:
    """Counts of a model: links, links with mass (bodies), joints, movable joints."""

    links: int
    bodies: int
    joints: int
    dof: int

    @staticmethod
    def of(model: RobotModel) -> "ModelSize":
        bodies = sum(1 for link in model.links
                     if link.inertial is not None and not is_zero_inertial(link.inertial))
        return ModelSize(len(model.links), bodies, len(model.joints), model.dof)


@dataclass(frozen=True)
class LockedJoint:
    """A movable joint of the description held still at ``position`` [rad or m; a compound
    joint (ball, planar): its configuration entries]; ``listed`` when the scene gives the
    position, else it lies outside the moving part and is locked at 0 (a compound joint at its
    kind's neutral configuration)."""

    name: str
    position: float | tuple[float, ...]
    listed: bool

    @property
    def shown(self) -> str:
        """The position as a report writes it: ``0.5``; a compound joint's configuration
        ``(0, 0, 0.38, 0.92)``."""
        if isinstance(self.position, tuple):
            return "(" + ", ".join(f"{x:g}" for x in self.position) + ")"
        return f"{self.position:g}"


@dataclass(frozen=True)
class MergedBody:
    """A moving body of the reduced model: the child link of ``joint`` with ``links`` (attached
    through fixed or locked joints) and ``payloads`` merged into it."""

    link: str
    joint: str
    links: tuple[str, ...]
    payloads: tuple[str, ...]


@dataclass(frozen=True)
class DerivationCost:
    """What deriving a model cost: seconds (None when not measured or not finished) and the
    operation count of each derived output (``("M", 1878)``, …)."""

    seconds: float | None
    operations: tuple[tuple[str, int], ...] = ()
    timeout: float | None = None  # set when the derivation did not finish within it
    error: str = ""

    @property
    def total_operations(self) -> int | None:
        return sum(n for _, n in self.operations) if self.operations else None

    def describe_time(self) -> str:
        if self.timeout is not None:
            return f"> {self.timeout:g} s (timeout)"
        if self.error:
            return f"failed ({self.error})"
        return "not measured" if self.seconds is None else f"{self.seconds:.2f} s"


@dataclass(frozen=True)
class ReductionReport:
    """What :func:`apply_scene` did, step by step (see the module docstring)."""

    robot: str
    scene: str
    description: str
    before: ModelSize
    after: ModelSize
    base: str
    tips: tuple[str, ...]
    moving: tuple[str, ...]
    world: str
    locked: tuple[LockedJoint, ...]
    merged: tuple[MergedBody, ...]
    dropped: tuple[str, ...]
    dropped_payloads: tuple[str, ...]
    planar: PlanarMotion | None
    notes: tuple[str, ...]
    outputs: tuple[str, ...]
    #: The scene's contacts (:class:`eomgen.model.Contact`); each frame is a link of the
    #: reduced model (a massless frame fixed to its body when the merge absorbed it).
    contacts: tuple = ()
    #: The six virtual joints a scene's ``floating_base`` put above the root (moving, but not
    #: the description's); empty without a floating base.
    virtual_joints: tuple[str, ...] = ()
    #: What the loops leave of the mechanism (:class:`eomgen.numeric.loop_checks.LoopMobility`:
    #: ``dof``, ``describe()``); None without loops.
    mobility: object = None

    def __repr__(self) -> str:
        """One line: the robot, the scene, what moves (the whole report: :meth:`markdown`)."""
        return (f"<ReductionReport of {self.robot!r} by scene {self.scene!r}: "
                f"{self.moving_summary()} ({reprs.names(self.moving)}); outputs "
                f"{reprs.names(self.outputs, most=8)}; {len(self.notes)} notes>")

    @property
    def locked_by_default(self) -> tuple[str, ...]:
        return tuple(j.name for j in self.locked if not j.listed)

    @property
    def moving_described(self) -> int:
        """How many of the description's own joints move (virtual joints not counted)."""
        return self.after.dof - len(self.virtual_joints)

    def moving_summary(self) -> str:
        """``"2 of 9 joints move"``; with a floating base ``"12 of 12 joints move, and the
        floating base's 6 virtual joints (18 in all)"``."""
        noun = "joint" if self.before.dof == 1 else "joints"
        text = f"{self.moving_described} of {self.before.dof} {noun} move"
        if self.virtual_joints:
            text += (f", and the floating base's {len(self.virtual_joints)} virtual joints "
                     f"({self.after.dof} in all)")
        return text

    def markdown(self, before: DerivationCost | None = None,
                 after: DerivationCost | None = None) -> str:
        """The report as a Markdown document; ``before`` and ``after`` are the derivation costs
        of the whole description and of the reduced model, when measured."""
        out = [f"# Scene report: {_md(self.robot)}", ""]
        out.append(f"Scene `{_md(self.scene)}` applied to robot `{_md(self.robot)}`."
                   + (f" {_md(self.description)}" if self.description else ""))
        out += ["", "## Effect", "",
                "| | whole description | with the scene | ratio |", "| --- | ---: | ---: | ---: |"]
        for label, a, b in (("links", self.before.links, self.after.links),
                            ("links with mass", self.before.bodies, self.after.bodies),
                            ("joints", self.before.joints, self.after.joints),
                            ("movable joints (dof)", self.before.dof, self.after.dof)):
            out.append(f"| {label} | {a} | {b} | {_ratio(a, b)} |")
        names = [n for n, _ in (after.operations if after else ())] or \
                [n for n, _ in (before.operations if before else ())]
        ops_before = dict(before.operations) if before else {}
        ops_after = dict(after.operations) if after else {}
        for name in names:
            a, b = ops_before.get(name), ops_after.get(name)
            out.append(f"| operations of {name} | {_or_dash(a)} | {_or_dash(b)} | {_ratio(a, b)} |")
        if before is not None or after is not None:
            b = after.seconds if after else None
            if before is not None and before.timeout is not None:
                speedup = "> " + _ratio(before.timeout, b)
            else:
                speedup = _ratio(before.seconds if before else None, b)
            out.append(f"| derivation time | "
                       f"{before.describe_time() if before else 'not measured'} | "
                       f"{after.describe_time() if after else 'not measured'} | {speedup} |")
        if before is None:
            out += ["", "The whole description was not derived for comparison "
                    "(`eomgen generate --explain` does it)."]
        out += ["", "Outputs: " + ", ".join(f"`{o}`" for o in self.outputs) + "."]
        out += ["", "## Moving part", "",
                f"Base `{_md(self.base)}`, "
                + ("tips " + ", ".join(f"`{_md(t)}`" for t in self.tips) if self.tips else
                   "no tips (every joint below the base)")
                + f"; moving: {len(self.moving)} joints, in this order: "
                + ", ".join(f"`{_md(j)}`" for j in self.moving) + ".",
                "", f"Fixed frame of the reduced model: {_md(self.world)}."]
        out += ["", "## Locked", ""]
        listed = [j for j in self.locked if j.listed]
        for j in listed:
            out.append(f"- `{_md(j.name)}` at {j.shown} (from the scene)")
        if self.locked_by_default:
            out.append(f"- at 0, because they lie outside the moving part and the scene does not "
                       f"list them ({len(self.locked_by_default)}): "
                       + ", ".join(f"`{_md(n)}`" for n in self.locked_by_default))
        if not self.locked:
            out.append("Nothing: every movable joint moves.")
        out += ["", "## Merged", "",
                "Links attached through fixed or locked joints, and payloads, merged into the "
                "moving body they hang from (composite inertia, parallel-axis theorem):", ""]
        merged_any = False
        for body in self.merged:
            parts = [f"`{_md(n)}`" for n in body.links] + \
                    [f"payload `{_md(n)}`" for n in body.payloads]
            if parts:
                merged_any = True
                out.append(f"- `{_md(body.link)}` (joint `{_md(body.joint)}`) ← " + ", ".join(parts))
        if not merged_any:
            out.append("- nothing to merge")
        out += ["", "## Dropped", "",
                "Rigidly attached to the world, so without influence on the moving joints "
                f"(the root link first), {len(self.dropped)} links: "
                + ", ".join(f"`{_md(n)}`" for n in self.dropped) + "."]
        for name in self.dropped_payloads:
            out.append(f"Payload `{_md(name)}` sits on a link fixed to the world: dropped.")
        out += ["", "## Planar motion", ""]
        if self.planar is None:
            out.append("Not planar: the moving joints' axes are not all parallel (revolute) and "
                       "perpendicular (prismatic) to one direction.")
        else:
            n = ", ".join(f"{x:.6g}" for x in self.planar.normal)
            out.append(f"Planar: every body moves in a plane with normal ({n}) in the root frame; "
                       f"gravity {self.planar.gravity}.")
        if self.notes:
            out += ["", "## Notes", ""] + [f"- {_md(note)}" for note in self.notes]
        return "\n".join(out) + "\n"


def _md(text: str) -> str:
    """Text safe inside Markdown inline code and prose: one line, no backticks."""
    return " ".join(str(text).split()).replace("`", "'")


def _or_dash(value) -> str:
    return "–" if value is None else str(value)


def _ratio(a, b) -> str:
    if a is None or b is None or b == 0:
        return "–"
    return f"{a / b:.1f}×"


class Reduction(NamedTuple):
    """The result of :func:`apply_scene`: the reduced model and the report."""

    model: RobotModel
    report: ReductionReport
