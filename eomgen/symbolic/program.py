"""Straight-line programs: symbolic expressions with named intermediate quantities.

Expression swell is what makes naive symbolic dynamics unusable past a few joints. eomgen never
builds one big expression: every non-trivial quantity (a sine, an entry of a rotation matrix, a
composite inertia, a Christoffel symbol) is *defined once* as a named intermediate symbol, and
later expressions refer to it by name. The result is a straight-line program
``x_k = f_k(q, qd, parameters, x_0 … x_{k-1})`` whose outputs (M, C, g, …) are small
expressions in the intermediates. Identical definitions are shared (hash-consing), numbers fold,
and zeros never get a name, so structural zeros propagate for free.

Printers turn a program into code directly; :meth:`Program.expand` substitutes the intermediates
back when full expressions in ``q`` are wanted (small teaching models, exact checks).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Mapping, NamedTuple, Sequence

import sympy as sp
from sympy.core.operations import LatticeOp

from .monomials import leads_with_minus, leads_with_negative_number, negated


class Tag(NamedTuple):
    """What an intermediate is, set where it is defined (never read back from its name).

    Attributes
    ----------
    family:
        The kind of quantity, e.g. ``"R"`` (an entry of a body's world rotation), ``"Ic"`` (of
        a composite inertia), ``"Gamma"`` (a Christoffel symbol): the keys of
        :data:`eomgen.codegen.backends.latex_backend.PROGRAM_NAMES` for the Lagrangian
        program.
    index:
        The joint numbers it belongs to (1-based, as in ``q_1``), then 0-based vector or
        matrix entries: ``Tag("R", (3, 0, 2))`` is entry (0, 2) of ``R_3``.
    """

    family: str
    index: tuple[int, ...] = ()


def as_tag(tag) -> Tag | None:
    """A :class:`Tag` from a Tag, ``(family, index...)`` or ``(family, (index...))``; None
    stays None."""
    if tag is None or isinstance(tag, Tag):
        return tag
    family, *index = tag
    if len(index) == 1 and isinstance(index[0], tuple):
        index = index[0]
    return Tag(family, tuple(int(i) for i in index))


class Assignment(tuple):
    """One ``(symbol, expression)`` step of a program, with the :class:`Tag` its builder gave
    it (``tag``, or None). Unpacks, compares and hashes as the pair.

    ``free`` is the expression's free symbols when its builder had them at hand (else None):
    :meth:`Program.pruned` reads them instead of walking the expression again (each
    ``derive`` prunes its program several times)."""

    def __new__(cls, symbol: sp.Symbol, expr: sp.Expr, tag: Tag | None = None,
                free: frozenset | None = None):
        self = super().__new__(cls, (symbol, expr))
        self.tag = tag
        self.free = free
        return self

    def __reduce__(self):
        return (Assignment, (self[0], self[1], self.tag))


def _is_trivial(expr: sp.Expr) -> bool:
    """Atoms, and a number times an atom, are used inline rather than named."""
    if expr.is_Atom:
        return True
    if expr.is_Mul and len(expr.args) == 2 and expr.args[0].is_Number and expr.args[1].is_Atom:
        return True
    return False


class ProgramBuilder:
    """Builds a straight-line program. Not thread-safe; one builder per derivation.

    Parameters
    ----------
    reserved:
        Names already in use (joint and parameter symbols); intermediates never take them.
    """

    def __init__(self, reserved: Iterable[str] = ()):
        self._reserved = set(reserved)
        self._names: set[str] = set()
        self._by_value: dict[sp.Expr, sp.Symbol] = {}
        # The free-symbol sets of the named expressions: an expression whose set is not among
        # them cannot be the negation of one (negating changes no symbol), so define skips
        # building ``-expr`` (SymPy distributes the sign over every term: a sixth of derive).
        self._symbol_sets: set[frozenset] = set()
        self.assignments: list[tuple[sp.Symbol, sp.Expr]] = []
        #: Work shared between programs built into this builder (e.g. the world-frame
        #: composites of :mod:`eomgen.symbolic.composite`), by a key of the caller's choice.
        self.memo: dict = {}

    @property
    def reserved(self) -> frozenset[str]:
        """The names intermediates never take."""
        return frozenset(self._reserved)

    def _fresh(self, hint: str) -> sp.Symbol:
        name = hint
        while name in self._names or name in self._reserved:
            name += "_"
        self._names.add(name)
        return sp.Symbol(name, real=True)

    def define(self, expr, hint: str = "x", tag=None, scaled: bool = False) -> sp.Expr:
        """Name ``expr`` unless it is trivial or already named; return what to use in its place.

        ``hint`` is the name wanted (made unique); ``tag`` says what the quantity is
        (:class:`Tag`, or ``(family, index...)``), for documents that group intermediates.
        An expression already named keeps its first name and tag. ``scaled``: name a number
        times an atom too (worth it when the quantity will be multiplied again, e.g. rotated:
        ``c·(k x)`` and ``s·(k x)`` then cost one product each instead of two)."""
        expr = sp.sympify(expr) if not isinstance(expr, sp.Basic) else expr
        if expr.is_Atom or (_is_trivial(expr) and not scaled):
            return expr
        if expr.is_Mul and expr.args[0] == -1 and len(expr.args) == 2 and expr.args[1].is_Atom:
            return expr
        known = self._by_value.get(expr)
        if known is not None:
            return known
        symbols = frozenset(expr.free_symbols)
        if symbols in self._symbol_sets:
            neg = self._by_value.get(negated(expr))
            if neg is not None:
                return -neg
        symbol = self._fresh(hint)
        self._by_value[expr] = symbol
        self._symbol_sets.add(symbols)
        self.assignments.append(Assignment(symbol, expr, as_tag(tag), symbols))
        return symbol

    def absorb(self, program: "Program") -> dict[str, sp.Matrix]:
        """Define ``program``'s assignments here and return its outputs in terms of this
        builder's names. Each keeps its name where free (a name another builder had to suffix
        with ``_`` loses the suffix first); a definition already made here is shared. The
        expressions are taken as they are (``program`` was built by a builder too), with their
        tags."""
        changed: dict = {}

        def moved(expr):
            return expr.xreplace(changed) if changed and expr.free_symbols & changed.keys() else expr

        for assignment in program.assignments:
            symbol, expr = assignment
            expr = moved(expr)
            known = self._by_value.get(expr)
            if known is not None:
                changed[symbol] = known
                continue
            new = self._fresh(symbol.name.rstrip("_"))
            if new != symbol:
                changed[symbol] = new
            self._by_value[expr] = new
            symbols = frozenset(expr.free_symbols)
            self._symbol_sets.add(symbols)
            self.assignments.append(Assignment(new, expr, getattr(assignment, "tag", None),
                                               symbols))
        return {name: matrix.applyfunc(moved) for name, matrix in program.outputs}

    def define_all(self, exprs: Sequence, hint: str, tag=None) -> tuple:
        """Define each entry of a vector, hinting names ``hint0, hint1, …``; entry ``k`` is
        tagged with ``tag``'s index followed by ``k``."""
        tag = as_tag(tag)
        return tuple(self.define(e, f"{hint}{k}",
                                 None if tag is None else Tag(tag.family, tag.index + (k,)))
                     for k, e in enumerate(exprs))


def entry_tag(tag, *entry) -> Tag | None:
    """The tag of one entry of a named vector or matrix: ``tag``'s index followed by the entry's
    indices (``entry_tag(("Ia", 3), 0, 2)`` is ``Tag("Ia", (3, 0, 2))``); None for no tag."""
    tag = as_tag(tag)
    return None if tag is None else Tag(tag.family, tag.index + tuple(entry))


def _leads_negative(expr: sp.Expr) -> bool:
    """Whether ``expr`` prints with a leading minus sign (one more operation than its negation
    when that negation can be absorbed where it is used: a constant factor, a subtraction)."""
    if expr.is_Add:  # printers put a term without a minus sign first when there is one
        return all(leads_with_minus(term) for term in expr.args)
    return expr.is_Mul and leads_with_negative_number(expr)


def name_expr(b: ProgramBuilder, expr, hint: str, tag=None, scaled: bool = False) -> sp.Expr:
    """``b.define(expr, hint, tag, scaled)``, but an expression that leads with a minus sign is
    named negated and used as ``−name``: the sign then folds into the products and sums that
    use it (its tag then says what the negated entry is: documents print the name's
    definition). What the recursive algorithms (Newton–Euler, CRBA, ABA) name their
    intermediates with.

    >>> b = ProgramBuilder()
    >>> x, y = sp.symbols("x y")
    >>> name_expr(b, -x*y - y, "t"), b.assignments
    (-t, [(t, x*y + y)])
    """
    expr = sp.sympify(expr)
    if _leads_negative(expr):
        return negated(b.define(negated(expr), hint, tag, scaled))
    return b.define(expr, hint, tag, scaled)


def name_exprs(b: ProgramBuilder, exprs, hint: str, tag=None, scaled: bool = False) -> tuple:
    """:func:`name_expr` of each entry, hinted ``hint0, hint1, …``; entry k is tagged with
    ``tag`` (``(family, index...)``) followed by k."""
    tag = as_tag(tag)
    return tuple(name_expr(b, e, f"{hint}{k}", None if tag is None else
                           Tag(tag.family, tag.index + (k,)), scaled) for k, e in enumerate(exprs))


def name_symmetric(b: ProgramBuilder, A, hint: str, tag=None) -> tuple:
    """Name the upper triangle of a symmetric 3×3 (:func:`name_expr`, hinted ``<hint><r><c>``)
    and mirror it; entry (r, c) is tagged with ``tag``'s index followed by r, c."""
    named = [[None] * 3 for _ in range(3)]
    for r in range(3):
        for c in range(r, 3):
            named[r][c] = named[c][r] = name_expr(b, A[r][c], f"{hint}{r}{c}",
                                                  entry_tag(tag, r, c))
    return tuple(tuple(row) for row in named)


def name_matrix(b: ProgramBuilder, A, hint: str, tag=None) -> tuple:
    """Name every entry of a 3×3 (:func:`name_expr`, hinted ``<hint><r><c>``); entry (r, c)
    is tagged with ``tag``'s index followed by r, c."""
    return tuple(tuple(name_expr(b, A[r][c], f"{hint}{r}{c}", entry_tag(tag, r, c))
                       for c in range(3)) for r in range(3))


def substituted(expr: sp.Expr, replace: Mapping[sp.Symbol, sp.Expr],
                done: dict | None = None) -> sp.Expr:
    """``expr`` with the symbols of ``replace`` replaced and the rest of its structure kept as
    it stands: sums, products and powers are rebuilt unevaluated from their new arguments (not
    flattened, sorted or simplified again, so that this stays linear in the size of ``expr``),
    other functions applied to theirs; what holds no replaced symbol is ``expr``'s own object.
    ``done`` remembers rebuilt subexpressions across calls with the same (growing) ``replace``.

    >>> x, y, t = sp.symbols("x y t")
    >>> substituted(2*x*y + sp.sin(x), {x: t + 1})
    2*y*(t + 1) + sin(t + 1)
    """
    done = {} if done is None else done

    def walk(e):
        if e.is_Symbol:
            return replace.get(e, e)
        if e.is_Atom:
            return e
        found = done.get(e)
        if found is None:
            args = tuple(walk(a) for a in e.args)
            if all(a is b for a, b in zip(args, e.args)):
                found = e
            elif e.is_Add or e.is_Mul or e.is_Pow:
                found = e.func(*args, evaluate=False)
            else:
                found = e.func(*args)
            done[e] = found
        return found

    return walk(expr)


def rough_operation_count(exprs: Iterable[sp.Expr]) -> int:
    """A fast estimate of the arithmetic operations of ``exprs``: one per argument of a sum or
    product beyond the first, per power and per function call (what :meth:`Program.operation_count`
    counts exactly with SymPy's slower ``count_ops``)."""
    total = 0
    stack = list(exprs)
    while stack:
        e = stack.pop()
        if e.is_Atom:
            continue
        args = e.args
        if e.is_Add or e.is_Mul:
            total += len(args) - 1 - (1 if e.is_Mul and args[0] in (-1, 1) else 0)
        else:
            total += 1
        stack.extend(args)
    return total


def count_ops(expr: sp.Expr) -> int:
    """SymPy's ``count_ops(expr)`` (``visual=False``), the same number, without the new
    expressions SymPy makes on the way (it negates every negative term and rebuilds every
    product to split it into a fraction): sums, products, powers with a positive exponent,
    numbers, symbols and functions are counted here; anything else (a division, a symbolic
    exponent, ``exp``, a piecewise) is handed to ``sp.count_ops`` whole.

    >>> x, y = sp.symbols("x y")
    >>> [count_ops(e) for e in (x - 2.5*y, -x*y, sp.sin(x)**2 - 1, x/y)]
    [2, 2, 3, 1]
    """
    if expr.is_Symbol:
        return 0
    if expr.is_Rational:
        return 0 if expr is sp.S.One else int(expr.p < 0) + int(expr.q != 1)
    if expr.is_Float:
        return 0
    if expr.is_Add:
        terms = expr.args
        total, negative = len(terms) - 1, 0
        for term in terms:
            if _negative_coefficient(term):
                negative += 1
                total += _count_negated(term)
            else:
                total += count_ops(term)
        return total + (negative == len(terms))
    if expr.is_Mul:
        args = expr.args
        if not all(_plain_factor(f) for f in args) or (
                args[0] is sp.S.NegativeOne and len(args) == 2 and args[1].is_Add):
            return int(sp.count_ops(expr))  # SymPy leaves −(x + y)'s own sum uncounted
        if _negative_coefficient(expr):
            return 1 + _count_negated(expr)
        return len(expr.args) - 1 + sum(count_ops(f) for f in expr.args)
    if expr.is_Pow:
        if expr.exp.is_Number and expr.exp > 0 and expr.base is not sp.S.Exp1:
            return 1 + count_ops(expr.base) + count_ops(expr.exp)
        return int(sp.count_ops(expr))
    if (isinstance(expr, sp.Function) and not isinstance(expr, (sp.exp, LatticeOp))
            and all(isinstance(a, sp.Expr) for a in expr.args)):
        return 1 + sum(count_ops(a) for a in expr.args)
    return int(sp.count_ops(expr))


def _negative_coefficient(expr: sp.Expr) -> bool:
    """SymPy's ``_coeff_isneg``: a negative number, or a product that leads with one."""
    c = expr.args[0] if expr.is_Mul else expr
    return c.is_Number and bool(c.is_extended_negative)


def _plain_factor(factor: sp.Expr) -> bool:
    """A factor that puts nothing in a product's denominator (SymPy's ``fraction``)."""
    if factor.is_Pow:
        return factor.exp.is_Number and factor.exp > 0
    if factor.is_Rational:
        return factor.q == 1
    return not isinstance(factor, sp.exp)


def _count_negated(expr: sp.Expr) -> int:
    """``count_ops(-expr)`` of a negative number or a product with a negative leading number
    whose factors are all plain (:func:`_plain_factor`), else SymPy's count of ``-expr``."""
    if expr.is_Float:
        return 0
    if expr.is_Rational:
        return int(expr.q != 1)
    if expr.is_Mul and all(_plain_factor(f) for f in expr.args):
        c, rest = expr.args[0], expr.args[1:]
        if c is sp.S.NegativeOne:  # −1·x·y → x·y
            return len(rest) - 1 + sum(count_ops(f) for f in rest)
        return len(expr.args) - 1 + _count_negated(c) + sum(count_ops(f) for f in rest)
    return int(sp.count_ops(-expr))


@dataclass(frozen=True)
class Program:
    """An immutable straight-line program with named outputs.

    Attributes
    ----------
    assignments:
        ``(symbol, expression)`` pairs in evaluation order; each expression uses only inputs and
        earlier symbols.
    outputs:
        Output name → SymPy Matrix in terms of inputs and intermediates.
    """

    assignments: tuple[tuple[sp.Symbol, sp.Expr], ...]
    outputs: tuple[tuple[str, sp.Matrix], ...]

    def output(self, name: str) -> sp.Matrix:
        return dict(self.outputs)[name]

    def pruned(self, names: Iterable[str]) -> "Program":
        """The program computing only the named outputs, with unused assignments removed."""
        names = list(names)
        outs = tuple((n, m) for n, m in self.outputs if n in names)
        needed: set[sp.Symbol] = set()
        for _, matrix in outs:
            needed |= matrix.free_symbols
        kept = []
        for assignment in reversed(self.assignments):
            symbol, expr = assignment
            if symbol in needed:
                kept.append(assignment)  # as it is, with its tag
                free = getattr(assignment, "free", None)
                needed |= expr.free_symbols if free is None else free
        return Program(tuple(reversed(kept)), outs)

    def tags(self) -> dict[sp.Symbol, Tag]:
        """The :class:`Tag` of every intermediate its builder tagged."""
        return {a[0]: a.tag for a in self.assignments
                if isinstance(a, Assignment) and a.tag is not None}

    def expanded(self) -> dict[sp.Symbol, sp.Expr]:
        """Map every intermediate to its full expression in the inputs.

        Sub-trees are shared, not copied, and the substituted expressions are not re-flattened
        or re-evaluated (``evaluate=False``): they keep the structure of the program, which is
        what keeps this linear in the program size.
        """
        full: dict[sp.Symbol, sp.Expr] = {}
        done: dict[sp.Expr, sp.Expr] = {}
        for symbol, expr in self.assignments:
            full[symbol] = substituted(expr, full, done)
        return full

    def expand(self, matrix: sp.Matrix, full: Mapping | None = None) -> sp.Matrix:
        """``matrix`` with every intermediate replaced by its full expression in the inputs."""
        full = self.expanded() if full is None else full
        return matrix.applyfunc(lambda e: e.xreplace(dict(full)) if e.free_symbols & full.keys() else e)

    def operation_count(self, names: Iterable[str] | None = None) -> int:
        """Arithmetic operations (SymPy ``count_ops``) of the assignments and outputs needed for
        the named outputs (all by default)."""
        program = self if names is None else self.pruned(names)
        total = sum(count_ops(expr) for _, expr in program.assignments)
        for _, matrix in program.outputs:
            total += sum(count_ops(e) for e in matrix)
        return int(total)
