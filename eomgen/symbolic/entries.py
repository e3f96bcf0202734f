"""One entry of a named result (:class:`eomgen.symbolic.named.ProgramMatrix`) as an ordinary
SymPy expression: ``M_1_1(q1, …, q5, m2, …)``, an applied function of the inputs the entry
depends on, which knows how to evaluate itself (:func:`program_entry`).

Why a function and not the entry written out: substituting a program's intermediates into
each other gives trees of 10⁸–10¹⁰ nodes for a 5- or 7-joint arm with symbolic inertias
(shared in memory, but every SymPy printer and ``simplify`` walks them as trees), and
multiplying them out takes minutes (26,102 terms for the M of a random 5-joint arm: 73 s).
The function is SymPy's own device for such values (an implemented function, as
``sympy.utilities.lambdify.implemented_function`` makes): ``sympy.lambdify`` finds its
implementation, ``evalf`` and ``subs`` work, ``latex`` and ``simplify`` take it like any other
function application.
"""

from __future__ import annotations

from typing import Sequence

import sympy as sp
from sympy.core.function import AppliedUndef, UndefinedFunction
from sympy.printing.numpy import NumPyPrinter
from mpmath.libmp import prec_to_dps


def inputs_of(definitions: Sequence[tuple[sp.Symbol, sp.Expr]], expr) -> set:
    """The symbols ``expr`` depends on through ``definitions`` (intermediates excluded)."""
    defined = dict(definitions)
    out: set = set()
    seen: set = set()
    stack = list(expr.free_symbols)
    while stack:
        symbol = stack.pop()
        if symbol in seen:
            continue
        seen.add(symbol)
        if symbol in defined:
            stack.extend(defined[symbol].free_symbols)
        else:
            out.add(symbol)
    return out


class EntryProgram:
    """The implementation of one entry: its expression in the intermediates and their
    definitions, evaluated for numbers (NumPy arrays too) given in the order of ``inputs``.
    Equal when the entries are (so that equal entries are equal SymPy functions)."""

    def __init__(self, value: sp.Expr, definitions: tuple, inputs: tuple):
        self.value, self.definitions, self.inputs = value, definitions, inputs
        self._hash = hash((value, definitions, inputs))
        self._compiled = None
        self._pruned = None

    def __eq__(self, other):
        return (isinstance(other, EntryProgram) and self._hash == other._hash
                and self.value == other.value and self.inputs == other.inputs
                and (self.definitions is other.definitions or self.definitions == other.definitions))

    def __hash__(self):
        return self._hash

    def __getstate__(self):
        # the compiled function is SymPy lambdify's (defined in a namespace of its own, not
        # importable): a cache, left out so that an entry, and the Dynamics holding it, pickle
        # after being evaluated; compiled again on first use
        return {**self.__dict__, "_compiled": None}

    @property
    def pruned(self) -> tuple:
        """The definitions the entry needs, in order."""
        if self._pruned is None:
            needed = set(self.value.free_symbols)
            kept = []
            for symbol, expr in reversed(self.definitions):
                if symbol in needed:
                    kept.append((symbol, expr))
                    needed |= expr.free_symbols
            self._pruned = tuple(reversed(kept))
        return self._pruned

    def __call__(self, *args):
        if self._compiled is None:  # compiled on first use: most entries are never evaluated
            subexpressions = list(self.pruned)
            self._compiled = sp.lambdify(self.inputs, self.value, "numpy",
                                         printer=_lambdify_printer(self.value),
                                         cse=lambda exprs: (subexpressions, exprs))
        return self._compiled(*args)

    def evaluate(self, args: Sequence[sp.Expr]) -> sp.Expr:
        """The value for SymPy numbers ``args`` (exact or at their precision), folded through
        the definitions in order."""
        rule = dict(zip(self.inputs, args))
        for symbol, expr in self.pruned:
            rule[symbol] = expr.xreplace(rule)
        return self.value.xreplace(rule)


class _PrintedOnce(NumPyPrinter):
    """The printer ``sympy.lambdify(..., "numpy")`` makes, remembering the text of each
    expression *object* it printed: the entries of one matrix share most of their definitions
    (the same objects), and each entry's ``lambdify`` would print them again. Keyed by
    identity (the object kept alive with its text), so the text is what SymPy prints."""

    #: Texts kept before the memory is emptied (it holds the expressions it printed).
    KEPT = 20_000

    def __init__(self, settings):
        super().__init__(settings)
        self._texts: dict[int, tuple[sp.Basic, str]] = {}

    def doprint(self, expr, assign_to=None):
        if assign_to is not None:
            return super().doprint(expr, assign_to)
        found = self._texts.get(id(expr))
        if found is None or found[0] is not expr:
            if len(self._texts) >= self.KEPT:
                self._texts.clear()
            found = self._texts[id(expr)] = (expr, super().doprint(expr))
        return found[1]


_PRINTERS: dict[frozenset, _PrintedOnce] = {}


def _lambdify_printer(value: sp.Expr) -> _PrintedOnce:
    """The printer ``sympy.lambdify(inputs, value, "numpy")`` would make (its settings, with
    the implemented functions of ``value`` as user functions), shared by the entries."""
    implemented = frozenset(f.func.__name__ for f in value.atoms(sp.Function)
                            if getattr(f.func, "_imp_", None) is not None)
    printer = _PRINTERS.get(implemented)
    if printer is None:
        printer = _PRINTERS[implemented] = _PrintedOnce({
            "fully_qualified_modules": False, "inline": True, "allow_unknown_functions": True,
            "user_functions": {name: name for name in implemented}})
    return printer


class ProgramEntry(AppliedUndef):
    """An entry of a named result applied to its inputs (see :func:`program_entry`)."""

    @property
    def program(self) -> EntryProgram:
        return type(self)._imp_

    @property
    def label(self) -> str:
        return type(self).label

    @classmethod
    def eval(cls, *args):
        # Numbers with a Float among them give a number, as sin(0.5) does (exact arguments
        # stay unevaluated: evalf gives the number).
        if args and all(a.is_number for a in args) and any(a.has(sp.Float) for a in args):
            prec = max(a._prec for a in args if a.is_Float) if any(a.is_Float for a in args) \
                else 53
            value = cls._imp_.evaluate([a.evalf(prec_to_dps(prec)) for a in args])
            return value.evalf(prec_to_dps(prec)) if value.is_number else None
        return None

    def _eval_evalf(self, prec):
        if not all(a.is_number for a in self.args):
            return None
        args = [a.evalf(prec) if not a.is_Rational else a for a in self.args]
        value = self.program.evaluate(args)
        return value.evalf(prec) if value.is_number else None

    def _sympystr(self, printer):
        return f"{self.label}({', '.join(printer._print(a) for a in self.args)})"

    def _latex(self, printer):
        name, *indices = self.label.split("_")
        sub = "_{" + ",".join(indices) + "}" if indices else ""
        args = ", ".join(printer._print(a) for a in self.args)
        return rf"{printer._print(sp.Symbol(name))}{sub}\left({args}\right)"


def program_entry(label: str, value: sp.Expr, definitions: tuple) -> sp.Expr:
    """``value`` (an expression in the intermediates of ``definitions``) as the SymPy
    expression ``label(inputs…)``: an applied function, real, of the inputs it depends on,
    whose implementation evaluates the definitions it needs (for ``sympy.lambdify``,
    ``evalf``, numbers given to ``subs``); ``value`` itself when it needs no definitions.

    ``label`` is a Python name (``M_1_1``); the function's own name adds a short mark of its
    definitions, so that two different entries of one label (the M of two robots) can share a
    ``lambdify``.

    Examples
    --------
    >>> x0, q1 = sp.symbols("x0 q1")
    >>> e = program_entry("A_1_1", x0 ** 2, ((x0, sp.cos(q1) + 1),))
    >>> e
    A_1_1(q1)
    >>> e.subs(q1, 0).evalf()
    4.00000000000000
    >>> float(sp.lambdify([q1], e)(0.0))
    4.0
    """
    inputs = inputs_of(definitions, value)
    if not value.free_symbols & {s for s, _ in definitions}:
        return value
    inputs = tuple(sorted(inputs, key=sp.default_sort_key))
    implementation = EntryProgram(value, tuple(definitions), inputs)
    name = f"{label}_{implementation._hash & 0xFFFFFF:06x}"
    function = UndefinedFunction(name, bases=(ProgramEntry,), _imp_=implementation, label=label,
                                 real=True)
    return function(*inputs)
