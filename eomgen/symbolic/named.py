"""Results of a straight-line program as SymPy-friendly objects: :class:`ProgramMatrix`.

Beyond teaching size, ``dyn.M``, ``dyn.C``, ``dyn.g`` and ``dyn.tau`` of :func:`eomgen.derive`
cannot always be written out: the expanded M of a 5-joint spatial arm has thousands of terms,
the Panda's τ tens of thousands, and substituting the program's intermediates back into each other gives trees that
SymPy's tools (``lambdify(..., cse=True)``, ``count_ops``, ``simplify``) walk for minutes. A
:class:`ProgramMatrix` is the honest form of such a result: the output matrix in terms of named
intermediates ``x_k`` plus their definitions (:attr:`ProgramMatrix.subexpressions`, each small),
which is what the code printers use. It indexes and multiplies like a matrix, substitutes,
evaluates numerically, lambdifies with its named subexpressions as the common subexpressions,
displays in a notebook, and :meth:`ProgramMatrix.expand` writes it out as an ordinary SymPy
matrix on request, stopping with a clear message when it grows past a limit. SymPy's own
functions (``sympify``, ``Matrix``, ``lambdify``, ``simplify``, ``latex``) take it through
:meth:`ProgramMatrix._sympy_`: the matrix written out where that is cheap, else its entries as
functions of their inputs that evaluate the program (:mod:`eomgen.symbolic.entries`).

Writing out is :mod:`eomgen.symbolic.expansion`: sparse polynomials in ``sin q_i``, ``cos q_i``,
the velocities and the parameters, reduced with ``sin² q_i + cos² q_i = 1`` after every
product, not SymPy's ``expand``.
"""

from __future__ import annotations

from typing import Iterable, Mapping, Sequence

import sympy as sp

from .entries import program_entry
# Also imported from here by dynamics.py and the tests (the error ProgramMatrix.expand raises).
from .expansion import ExpansionTooLargeError, expand_program

#: :meth:`ProgramMatrix.expand` stops when an intermediate result passes this many terms, unless
#: called with ``max_terms=None``.
EXPAND_MAX_TERMS = 200_000

#: ``dyn.M`` (and C, g, P, tau) of :func:`eomgen.derive` beyond teaching size is written out when
#: that takes at most this many term operations (about a second), else left named.
AUTO_EXPAND_WORK = 1_000_000

#: Subexpressions shown by :meth:`ProgramMatrix._repr_latex_` before "… and k more".
LATEX_MAX_SUBEXPRESSIONS = 40


def _prune(definitions: Sequence[tuple[sp.Symbol, sp.Expr]], exprs: Iterable[sp.Expr]):
    """The definitions ``exprs`` need (directly or through other definitions), in order."""
    needed: set = set()
    for expr in exprs:
        needed |= expr.free_symbols
    kept = []
    for symbol, expr in reversed(definitions):
        if symbol in needed:
            kept.append((symbol, expr))
            needed |= expr.free_symbols
    return tuple(reversed(kept))


def _entries(value) -> list[sp.Expr]:
    return list(value) if isinstance(value, sp.MatrixBase) else [value]


class ProgramMatrix:
    """A matrix (or, from indexing, a scalar) of SymPy expressions in named intermediates,
    with their definitions: a result of :func:`eomgen.derive` too large to write out.

    ``M = ProgramMatrix("M", entries, definitions)`` stands for ``entries`` with every
    intermediate ``x_k`` replaced by its definition, in order. Operations that stay cheap keep
    that form: indexing and slicing, ``.T``, ``+``, ``-``, ``*`` with SymPy matrices, numbers and
    other results of the same program, :meth:`subs` / :meth:`xreplace` (numbers fold through
    the definitions; with every input given the result is an ordinary SymPy matrix of numbers),
    :meth:`evalf`, :meth:`lambdify`. :meth:`expand` writes it out as an ordinary SymPy matrix
    after checking the size.

    Parameters
    ----------
    name:
        What it is (``"M"``, ``"C"``, ``"g"``, ``"tau"``), for messages and display.
    value:
        A SymPy Matrix (or scalar expression) in the inputs and the intermediates.
    definitions:
        ``(symbol, expression)`` pairs in evaluation order (a program's assignments; those the
        value does not need are ignored).

    Examples
    --------
    >>> x0, q1 = sp.symbols("x0 q1")
    >>> A = ProgramMatrix("A", sp.Matrix([[x0, 1], [1, x0 ** 2]]), [(x0, sp.cos(q1) + 1)])
    >>> A.shape, A.free_symbols
    ((2, 2), {q1})
    >>> A.expand()
    Matrix([
    [cos(q1) + 1,                          1],
    [          1, cos(q1)**2 + 2*cos(q1) + 1]])
    >>> A.subs(q1, 0)
    Matrix([
    [2, 1],
    [1, 4]])
    """

    #: Above a SymPy Matrix's (10.01), so that ``Matrix * program_matrix`` calls our ``__rmul__``.
    _op_priority = 20.0

    #: Not a sequence to SymPy (``sympy.utilities.iterables.iterable``): SymPy's functions take
    #: it whole, through :meth:`_sympy_` and the printing methods, not entry by entry.
    _iterable = False
    #: NumPy defers ``array * program_matrix`` to :meth:`__rmul__` (the object defines
    #: ``__array__`` for ``sympy.Matrix(program_matrix)``).
    __array_ufunc__ = None

    def __init__(self, name: str, value, definitions: Sequence[tuple[sp.Symbol, sp.Expr]],
                 label: str | None = None):
        self.name = name
        self.value = sp.ImmutableMatrix(value) if isinstance(value, sp.MatrixBase) else sp.sympify(value)
        self.definitions = tuple(definitions)
        self.label = label or name
        self._pruned = None
        self._sympy_form = None
        self._failed_work = None  # the work limit an expansion of it passed

    # --- what it is --------------------------------------------------------------------------
    @property
    def is_Matrix(self) -> bool:
        return isinstance(self.value, sp.MatrixBase)

    @property
    def subexpressions(self) -> tuple[tuple[sp.Symbol, sp.Expr], ...]:
        """The ``(symbol, definition)`` pairs the value needs, in evaluation order."""
        if self._pruned is None:
            self._pruned = _prune(self.definitions, _entries(self.value))
        return self._pruned

    @property
    def free_symbols(self) -> set[sp.Symbol]:
        """The inputs (joint variables, parameters) it depends on; intermediates excluded."""
        defined = {s for s, _ in self.subexpressions}
        out = set(self.value.free_symbols)
        for _, expr in self.subexpressions:
            out |= expr.free_symbols
        return out - defined

    @property
    def shape(self) -> tuple[int, ...]:
        return self.value.shape if self.is_Matrix else ()

    @property
    def rows(self) -> int:
        return self.value.rows

    @property
    def cols(self) -> int:
        return self.value.cols

    def __len__(self) -> int:
        return len(self.value)

    def __iter__(self):
        return (self._wrap(e) for e in self.value)

    def __getitem__(self, key):
        label = None
        if isinstance(key, int) and self.is_Matrix:
            key = divmod(key % len(self.value), self.cols)
        if isinstance(key, tuple) and all(isinstance(k, int) for k in key) and self.is_Matrix:
            i, j = key[0] % self.rows, key[1] % self.cols
            label = self._entry_label(i, j)
        return self._wrap(self.value[key], label=label)

    def _entry_label(self, i: int, j: int) -> str:
        """``M_2_3`` for ``M[1, 2]``, ``g_2`` for ``g[1]`` (1-based, as in the textbooks)."""
        return f"{self.name}_{i + 1}" if self.cols == 1 else f"{self.name}_{i + 1}_{j + 1}"

    @property
    def T(self) -> "ProgramMatrix":
        return self._wrap(self.value.T)

    def _wrap(self, value, definitions=None, label=None):
        """``value`` as a ProgramMatrix over these definitions, or plain SymPy when it needs
        none (a structural zero, an entry in the inputs only)."""
        definitions = self.definitions if definitions is None else definitions
        defined = {s for s, _ in definitions}
        if not any(e.free_symbols & defined for e in _entries(value)):
            return value
        return ProgramMatrix(self.name, value, definitions, label)

    # --- arithmetic ----------------------------------------------------------------------------
    def _other(self, other):
        """``(value, definitions)`` of an operand: a ProgramMatrix of the same program (or of
        one whose definitions agree) or anything SymPy takes."""
        if isinstance(other, ProgramMatrix):
            if other.definitions is self.definitions:
                return other.value, self.definitions
            mine = dict(self.definitions)
            merged = list(self.definitions)
            for symbol, expr in other.definitions:
                if symbol not in mine:
                    merged.append((symbol, expr))
                elif mine[symbol] != expr:
                    raise ValueError(f"{self.name} and {other.name} define {symbol} differently")
            return other.value, tuple(merged)
        if isinstance(other, (list, tuple)):
            other = sp.Matrix(other)
        return (other if isinstance(other, sp.MatrixBase) else sp.sympify(other)), self.definitions

    def __add__(self, other):
        value, definitions = self._other(other)
        return self._wrap(self.value + value, definitions)

    __radd__ = __add__

    def __sub__(self, other):
        value, definitions = self._other(other)
        return self._wrap(self.value - value, definitions)

    def __rsub__(self, other):
        value, definitions = self._other(other)
        return self._wrap(value - self.value, definitions)

    def __mul__(self, other):
        value, definitions = self._other(other)
        return self._wrap(self.value * value, definitions)

    def __rmul__(self, other):
        value, definitions = self._other(other)
        return self._wrap(value * self.value, definitions)

    def __matmul__(self, other):
        return self.__mul__(other)

    def __rmatmul__(self, other):
        return self.__rmul__(other)

    def __truediv__(self, other):
        return self._wrap(self.value / sp.sympify(other))

    def __neg__(self):
        return self._wrap(-self.value)

    def __getattr__(self, attribute):
        if attribute.startswith("_"):
            raise AttributeError(attribute)
        raise AttributeError(
            f"ProgramMatrix ({self.name}, in named subexpressions) has no {attribute!r}: call "
            ".expand() for an ordinary SymPy matrix first")

    # --- substitution and numbers ------------------------------------------------------------
    def xreplace(self, rule: Mapping):
        """Replace inputs (symbols) by values through the definitions: definitions that become
        numbers are folded into the ones after them. An ordinary SymPy matrix (or expression)
        when nothing named is left, else a smaller ProgramMatrix."""
        rule = {sp.sympify(k): sp.sympify(v) for k, v in dict(rule).items()}
        defined = {s for s, _ in self.subexpressions}
        if rule.keys() & defined:
            raise ValueError("substitute inputs (joint variables, parameters), not intermediates")
        kept = []
        for symbol, expr in self.subexpressions:
            new = expr.xreplace(rule)
            if new.is_Number:
                rule[symbol] = new
            else:
                kept.append((symbol, new))
        value = self.value.xreplace(rule)
        return self._wrap(value, tuple(kept))

    def subs(self, *args, **kwargs):
        """Like SymPy's ``subs`` (``subs(x, 1)``, ``subs({x: 1})``, ``subs([(x, 1)])``) for
        inputs: see :meth:`xreplace`."""
        if len(args) == 2:
            rule = {args[0]: args[1]}
        elif len(args) == 1:
            rule = dict(args[0])
        else:
            raise TypeError("subs takes a mapping, a list of pairs, or old and new")
        return self.xreplace(rule)

    def evalf(self, n: int = 15, subs: Mapping | None = None):
        """Numerical value with ``n`` digits, the inputs given in ``subs`` (all of them: else a
        ValueError naming those missing)."""
        value = self.xreplace(subs or {})
        if isinstance(value, ProgramMatrix):
            missing = ", ".join(sorted(str(s) for s in value.free_symbols))
            raise ValueError(f"{self.name}: evalf needs values for {missing}")
        return value.evalf(n)

    n = evalf

    def lambdify(self, args, modules="numpy", **kwargs):
        """``sympy.lambdify(args, self)`` with the named subexpressions as its common
        subexpressions: a function that evaluates the program, not the expanded matrix."""
        subexpressions = list(self.subexpressions)
        return sp.lambdify(args, self.value, modules,
                           cse=lambda exprs: (subexpressions, exprs), **kwargs)

    # --- written out ---------------------------------------------------------------------------
    def expand(self, max_terms: int | None = EXPAND_MAX_TERMS, max_work: int | None = None):
        """The ordinary SymPy matrix (or expression): every intermediate substituted, products
        multiplied out, ``sin² q_i + cos² q_i = 1`` applied (see :func:`expand_program`).

        The size of the result is not known before: it depends on cancellations (the M of the
        6-joint PUMA 560 expands to 262 terms, that of a 5-joint arm with general axes and
        offsets to tens of thousands). So the expansion checks as it goes, and stops.

        Parameters
        ----------
        max_terms:
            Stop when an intermediate result passes this many terms; ``None`` forces the
            expansion whatever its size.
        max_work:
            Stop after this many term operations (about a second per 10⁶); ``None``: no limit.

        Raises
        ------
        ExpansionTooLargeError
            Naming the limit passed and the way out.
        """
        try:
            entries = expand_program(self.subexpressions, _entries(self.value), max_terms,
                                     max_work)
        except ExpansionTooLargeError as error:
            if max_work is not None:
                self._failed_work = max(self._failed_work or 0, max_work)
            raise ExpansionTooLargeError(
                f"{self.name}: {error}. The named form (.subexpressions, .subs, .evalf, "
                ".lambdify, dyn.lambdify()) needs no expansion; .expand(max_terms=None) "
                "forces it") from None
        if not self.is_Matrix:
            return entries[0]
        return sp.Matrix(self.rows, self.cols, entries)

    as_explicit = expand

    # --- to SymPy ------------------------------------------------------------------------------
    def _sympy_(self):
        """What SymPy's functions see (``sympify``, ``simplify``, ``lambdify``, ``Matrix``, the
        printers): an ordinary SymPy matrix (or expression) of the same value. Written out
        (:meth:`expand`) when that takes at most :data:`AUTO_EXPAND_WORK` term operations;
        else each entry written out within its share of that work, or, when that is not
        enough, the entry as a function of its inputs that evaluates the definitions it
        needs (:func:`eomgen.symbolic.entries.program_entry`: ``M_1_1(q1, …)``). Computed
        once."""
        if self._sympy_form is None:
            self._sympy_form = self._as_sympy()
        return self._sympy_form

    def _as_sympy(self):
        if (self._failed_work or 0) < AUTO_EXPAND_WORK:
            try:
                written = self.expand(max_work=AUTO_EXPAND_WORK)
                return sp.ImmutableMatrix(written) if self.is_Matrix else written
            except (ExpansionTooLargeError, NotImplementedError):
                pass
        if not self.is_Matrix:
            return program_entry(self.label, self.value, self.subexpressions)
        share = AUTO_EXPAND_WORK // len(self.value)
        entries = []
        for k, entry in enumerate(self.value):
            i, j = divmod(k, self.cols)
            needed = _prune(self.subexpressions, [entry])
            try:
                [written] = expand_program(needed, [entry], None, share)
            except (ExpansionTooLargeError, NotImplementedError):
                written = program_entry(self._entry_label(i, j), entry, needed)
            entries.append(written)
        return sp.ImmutableMatrix(self.rows, self.cols, entries)

    @property
    def args(self) -> tuple:
        """``(self._sympy_(),)``: where ``sympy.lambdify`` looks for the implementations of
        the entries' functions."""
        return (self._sympy_(),)

    def __array__(self, dtype=None, copy=None):
        # NumPy is imported here, when an array is asked for: deriving never needs it.
        import numpy as np

        value = self._sympy_()
        if self.is_Matrix:
            return np.array(value.tolist(), dtype=object if dtype is None else dtype)
        return np.array(value, dtype=object if dtype is None else dtype)

    def _latex(self, printer):
        return printer._print(self._sympy_())

    def _sympystr(self, printer):
        return printer._print(self._sympy_())

    def _pretty(self, printer):
        return printer._print(self._sympy_())

    def __repr__(self) -> str:
        shape = "×".join(map(str, self.shape)) if self.is_Matrix else "scalar"
        return (f"ProgramMatrix({self.name}, {shape}, in {len(self.subexpressions)} named "
                "subexpressions; .expand() writes it out)")

    def _repr_latex_(self) -> str:
        shown = self.subexpressions[:LATEX_MAX_SUBEXPRESSIONS]
        lines = [f"{sp.latex(sp.Symbol(self.name))} = {sp.latex(self.value)}"]
        if shown:
            lines.append(r"\text{where}")
            lines += [f"{sp.latex(s)} = {sp.latex(e)}" for s, e in shown]
        more = len(self.subexpressions) - len(shown)
        if more:
            lines.append(rf"\text{{… and {more} more (.subexpressions)}}")
        return "$$\\begin{aligned}" + r"\\ ".join("&" + line for line in lines) + \
            r"\end{aligned}$$"
