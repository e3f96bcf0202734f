"""Reading shared by eomgen's two YAML formats (eomgen robot YAML and DH tables).

Safety: a document is parsed with a subclass of PyYAML's ``SafeLoader`` (plain data only: no
Python objects are ever constructed) that additionally refuses

* aliases (``*name``), so that "billion laughs" documents cannot expand,
* duplicate keys (PyYAML would silently keep the last one),
* documents nested deeper than :data:`MAX_DEPTH` or with more than :data:`MAX_NODES` nodes,
* files larger than :data:`MAX_BYTES`.

Values are checked by :class:`Reader`, which turns every problem into a one-line
:class:`~eomgen.errors.DescriptionError` naming the file and the element
(``links[2] 'link2' inertia``): a :class:`~eomgen.errors.SchemaError` for the document's
structure, an :class:`~eomgen.errors.InvalidNumberError` for values and a
:class:`~eomgen.errors.ParameterError` for parameter names and undeclared symbols. Numbers and expressions go through
:func:`eomgen.model.expressions.parse_scalar` only; every symbol must be declared under
``parameters``.
"""

from __future__ import annotations

import difflib
import math
import re
from pathlib import Path
from typing import Iterable

import sympy as sp
import yaml

from ..common.reading import not_regular
from ..errors import (
    DescriptionError,
    InvalidNumberError,
    ParameterError,
    SchemaError,
    TooLargeError,
    UnreadableFileError,
    YAMLFormatError,
    one_line,
)
from ..model.expressions import check_parameter_name, parse_scalar
from ..model import Actuator, Mat3, Parameter, Vec3, parameter_symbol, scalar

MAX_BYTES = 1024 * 1024
MAX_NODES = 100_000
MAX_DEPTH = 32

#: Link and joint names: used in generated code and LaTeX, so kept to a safe alphabet.
NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_.\-]{0,63}$")

#: Keys of an actuator mapping (robot YAML ``joints[i] actuator``, scene ``actuators``).
ACTUATOR_KEYS = ("armature", "rotor_inertia", "gear_ratio", "damping", "friction",
                 "friction_width", "stiffness")

INERTIA_KEYS = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
_INERTIA_INDEX = {
    "ixx": (0, 0), "iyy": (1, 1), "izz": (2, 2), "ixy": (0, 1), "ixz": (0, 2), "iyz": (1, 2),
}


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


class _LimitError(yaml.composer.ComposerError):
    """A document beyond :data:`MAX_NODES` or :data:`MAX_DEPTH`."""


class _Loader(yaml.SafeLoader):
    """``yaml.SafeLoader`` refusing aliases, duplicate keys, deep nesting and huge documents."""

    def __init__(self, stream):
        super().__init__(stream)
        self._nodes = 0
        self._depth = 0

    def compose_node(self, parent, index):
        if self.check_event(yaml.AliasEvent):
            event = self.peek_event()
            raise yaml.composer.ComposerError(
                None, None, "aliases (*name) are not allowed in robot descriptions",
                event.start_mark)
        self._nodes += 1
        if self._nodes > MAX_NODES:
            raise _LimitError(
                None, None, f"document has more than {MAX_NODES} nodes", self.peek_event().start_mark)
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                raise _LimitError(
                    None, None, f"document is nested deeper than {MAX_DEPTH} levels",
                    self.peek_event().start_mark)
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            seen = set()
            for key_node, _ in node.value:
                if key_node.tag == "tag:yaml.org,2002:merge":
                    continue
                key = self.construct_object(key_node, deep=True)
                try:
                    duplicate = key in seen
                except TypeError:  # unhashable key: the base class reports it
                    continue
                if duplicate:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"duplicate key {key!r}", key_node.start_mark)
                seen.add(key)
        return super().construct_mapping(node, deep)


def read_document(path: Path | str, text: str | None = None) -> dict:
    """Parse the YAML document in ``path`` (or ``text``, labelled ``path``) into a dict.

    Raises
    ------
    UnreadableFileError
        When the file cannot be read or is not UTF-8.
    TooLargeError
        When the file is larger than :data:`MAX_BYTES`, or the document has more than
        :data:`MAX_NODES` nodes or is nested deeper than :data:`MAX_DEPTH`.
    YAMLFormatError
        When it is not valid YAML, or uses aliases, duplicate keys or Python tags.
    InvalidNumberError
        For an integer too long to read.
    SchemaError
        When the document is empty or its top level is not a mapping.
    """
    source = str(path)
    if text is None:
        path = Path(path)
        problem = not_regular(path)
        if problem is not None:
            raise UnreadableFileError(source, "", problem)
        try:
            size = path.stat().st_size
        except OSError as exc:
            raise UnreadableFileError(source, "", f"cannot read file ({exc.strerror})") from None
        if size > MAX_BYTES:
            raise TooLargeError(source, "", f"file larger than {MAX_BYTES} bytes")
        try:
            text = path.read_bytes().decode("utf-8")
        except UnicodeDecodeError as exc:
            raise UnreadableFileError(source, "", f"not UTF-8 text ({exc.reason})") from None
        except OSError as exc:
            raise UnreadableFileError(source, "", f"cannot read file ({exc.strerror})") from None
    elif len(text.encode("utf-8")) > MAX_BYTES:
        raise TooLargeError(source, "", f"text larger than {MAX_BYTES} bytes")
    try:
        data = yaml.load(text, Loader=_Loader)  # noqa: S506 (a SafeLoader subclass)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = exc.problem or exc.context or "syntax error"
        kind = TooLargeError if isinstance(exc, _LimitError) else YAMLFormatError
        raise kind(source, "", _one_line(f"not valid YAML: {problem}{where}")) from None
    except yaml.YAMLError as exc:
        raise YAMLFormatError(source, "", _one_line(f"not valid YAML: {exc}")) from None
    except RecursionError:
        raise TooLargeError(source, "", "not valid YAML: nested too deeply") from None
    except ValueError as exc:  # an integer beyond Python's digit limit for int("...")
        raise InvalidNumberError(source, "", one_line(f"a number is too long to read ({exc})")
                                 ) from None
    if data is None:
        raise SchemaError(source, "", "empty document")
    if not isinstance(data, dict):
        raise SchemaError(
            source, "", f"the document must be a mapping of keys, not a {_kind(data)}")
    return data


def top_level_key(text: str, key: str) -> bool:
    """Whether ``key:`` starts a line of ``text`` (a top-level block-mapping key).

    Used by the ``sniff`` functions: a regular expression, no YAML parsing.
    """
    pattern = rf"^(?:{key}|\"{key}\"|'{key}')[ \t]*:(?:[ \t]|$)"
    return re.search(pattern, text, re.MULTILINE) is not None


def _kind(value) -> str:
    if isinstance(value, bool):
        return "boolean"
    if isinstance(value, (int, float)):
        return "number"
    if isinstance(value, str):
        return "string"
    if isinstance(value, list):
        return "list"
    if isinstance(value, dict):
        return "mapping"
    if value is None:
        return "null"
    return type(value).__name__


class Reader:
    """Checks values of one document; every error names ``source`` and the element.

    Parameters are declared first (:meth:`read_parameters`); afterwards :meth:`scalar` refuses
    symbols that were not declared and records those that are used.
    """

    def __init__(self, source: str):
        self.source = source
        self.declared: dict[str, Parameter] = {}
        self.used: set[str] = set()

    def error(self, where: str, problem: str, kind: type[DescriptionError] = SchemaError
              ) -> DescriptionError:
        """The exception to raise: ``kind`` (a structural problem by default) naming the file
        and ``where``."""
        return kind(self.source, _one_line(where), _one_line(problem))

    # -- structure ------------------------------------------------------------------------------

    def mapping(self, value, where: str, required: Iterable[str] = (),
                optional: Iterable[str] = ()) -> dict:
        """Check that ``value`` is a mapping with string keys, all required keys, no others."""
        required, optional = tuple(required), tuple(optional)
        if not isinstance(value, dict):
            raise self.error(where, f"expected a mapping, got a {_kind(value)}")
        allowed = required + tuple(k for k in optional if k not in required)
        for key in value:
            if not isinstance(key, str):
                raise self.error(where, f"key {key!r} is not a string")
            if key not in allowed:
                hint = difflib.get_close_matches(key, allowed, n=1)
                suggestion = f"; did you mean '{hint[0]}'?" if hint else ""
                raise self.error(
                    where, f"unknown key {key!r} (allowed: {', '.join(allowed)}){suggestion}")
        for key in required:
            if key not in value:
                raise self.error(where, f"missing required key '{key}'")
        return value

    def named(self, entry, where: str) -> str:
        """``where`` followed by the entry's name when it has a valid one (for messages about
        the entry as a whole: ``links[2] 'link2'``)."""
        if isinstance(entry, dict) and isinstance(entry.get("name"), str) \
                and NAME.match(entry["name"]):
            return f"{where} '{entry['name']}'"
        return where

    def sequence(self, value, where: str, allow_empty: bool = False) -> list:
        if not isinstance(value, list):
            raise self.error(where, f"expected a list, got a {_kind(value)}")
        if not value and not allow_empty:
            raise self.error(where, "the list is empty")
        return value

    def text(self, value, where: str) -> str:
        if not isinstance(value, str):
            raise self.error(where, f"expected text, got a {_kind(value)}")
        if len(value) > 1000:
            raise self.error(where, "text longer than 1000 characters")
        return _one_line(value)

    def name(self, value, where: str) -> str:
        """A link or joint name: letters, digits, ``_ . -``, starting with a letter or ``_``."""
        if not isinstance(value, str):
            raise self.error(where, f"name must be text, got a {_kind(value)}")
        if not NAME.match(value):
            raise self.error(
                where, f"name {value[:40]!r} must start with a letter or _ and use only letters, "
                "digits, _ . - (at most 64 characters)")
        return value

    def choice(self, value, where: str, choices: Iterable[str]) -> str:
        choices = tuple(choices)
        if not isinstance(value, str) or value not in choices:
            shown = repr(value) if isinstance(value, str) else f"a {_kind(value)}"
            raise self.error(where, f"{shown} is not one of: {', '.join(choices)}")
        return value

    # -- parameters and values -----------------------------------------------------------------

    def read_parameters(self, value, where: str = "parameters") -> None:
        """Declare parameters from ``{name: number | null | {value, description}}``."""
        if value is None:
            return
        if not isinstance(value, dict):
            raise self.error(where, f"expected a mapping of name: value, got a {_kind(value)}")
        for key, entry in value.items():
            here = f"{where} '{key}'"
            if not isinstance(key, str):
                raise self.error(where, f"parameter name {key!r} is not text", ParameterError)
            try:
                check_parameter_name(key)
            except ValueError as exc:
                raise self.error(here, str(exc), ParameterError) from None
            description = ""
            if isinstance(entry, dict):
                self.mapping(entry, here, optional=("value", "description"))
                if "description" in entry:
                    description = self.text(entry["description"], f"{here} description")
                raw = entry.get("value")
            else:
                raw = entry
            number = None if raw is None else self.number(raw, f"{here} value")
            self.declared[key] = Parameter(parameter_symbol(key), number, description)

    def number(self, value, where: str) -> float:
        """A plain number, or an expression without symbols (``1/12``, ``pi/2``)."""
        try:
            expr = parse_scalar(value)
        except ValueError as exc:
            raise self.error(where, str(exc), InvalidNumberError) from None
        if expr.free_symbols:
            raise self.error(where, f"expected a number, got {value!r} which uses symbols",
                             InvalidNumberError)
        out = float(expr)
        if not math.isfinite(out):
            raise self.error(where, "not a finite number", InvalidNumberError)
        return out

    def scalar(self, value, where: str) -> sp.Expr:
        """A number or an expression in declared parameters, as a SymPy scalar."""
        try:
            expr = parse_scalar(value)
        except ValueError as exc:
            raise self.error(where, str(exc), InvalidNumberError) from None
        for symbol in sorted(expr.free_symbols, key=str):
            if symbol.name not in self.declared:
                raise self.error(
                    where, f"symbol '{symbol.name}' is not declared under 'parameters' "
                    f"(add e.g. '{symbol.name}: {{value: 1.0}}')", ParameterError)
            self.used.add(symbol.name)
        return scalar(expr)

    def vector(self, value, where: str) -> Vec3:
        if not isinstance(value, list) or len(value) != 3:
            shown = f"{len(value)} entries" if isinstance(value, list) else f"a {_kind(value)}"
            raise self.error(where, f"expected a list of 3 values [x, y, z], got {shown}")
        return tuple(self.scalar(v, f"{where}[{i}]") for i, v in enumerate(value))  # type: ignore

    def inertia(self, value, where: str) -> Mat3:
        """``{ixx, iyy, izz, ixy, ixz, iyz}`` (missing entries are 0) as a symmetric 3×3."""
        self.mapping(value, where, optional=INERTIA_KEYS)
        m = [[sp.Integer(0)] * 3 for _ in range(3)]
        for key, entry in value.items():
            i, j = _INERTIA_INDEX[key]
            m[i][j] = m[j][i] = self.scalar(entry, f"{where} {key}")
        return tuple(tuple(row) for row in m)  # type: ignore[return-value]

    def actuator_values(self, value, where: str) -> dict[str, sp.Expr]:
        """The values of an actuator mapping (:data:`ACTUATOR_KEYS`; see
        :class:`~eomgen.model.Actuator`): ``armature`` or ``rotor_inertia`` with
        ``gear_ratio`` (not both), ``damping``, ``friction``, ``friction_width``,
        ``stiffness``; numbers or expressions in declared parameters. Physical checks are
        :func:`eomgen.model.check_actuator`'s; :meth:`Actuator.updated
        <eomgen.model.Actuator.updated>` makes the actuator."""
        self.mapping(value, where, optional=ACTUATOR_KEYS)
        values = {key: self.scalar(entry, f"{where} {key}") for key, entry in value.items()}
        if "armature" in values and ("rotor_inertia" in values or "gear_ratio" in values):
            raise self.error(where, "give either 'armature' or 'rotor_inertia' with "
                             "'gear_ratio' (armature = gear_ratio² · rotor_inertia), not both")
        return values

    def actuator(self, value, where: str) -> Actuator:
        """The :class:`~eomgen.model.Actuator` of a mapping (see :meth:`actuator_values`)."""
        values = self.actuator_values(value, where)
        if "gear_ratio" in values and "rotor_inertia" not in values:
            raise self.error(where, "'gear_ratio' given without 'rotor_inertia'")
        return Actuator().updated(values)

    def used_parameters(self) -> tuple[Parameter, ...]:
        """Declared parameters the document uses, in declaration order."""
        return tuple(p for name, p in self.declared.items() if name in self.used)
