"""The scalar algebra under the spatial one (eomgen.symbolic.monomials: mul, total, negated) and
the cross product built on it, which make the commonest products, sums and negations of the
recursions directly: each is SymPy's own result, argument for argument (so that programs and
the generated code do not change)."""

from __future__ import annotations

import random

import sympy as sp

from eomgen.symbolic.monomials import mul, negated, total
from eomgen.symbolic.spatial import cross

SYMBOLS = sp.symbols("a b c d e f", real=True)
NUMBERS = [sp.Float(2.5), sp.Float(-0.5), sp.Float(1.0), sp.Float(-1.0), sp.Integer(3),
           sp.Integer(-1), sp.Integer(2), sp.Rational(1, 3), sp.Rational(-2, 7)]


def _sums(count: int, seed: int = 1):
    """Random sums of monomials (a number or none times distinct symbols), some with a
    number term, some whose terms combine (the same symbols twice)."""
    rng = random.Random(seed)
    for _ in range(count):
        terms = []
        for _ in range(rng.randint(2, 5)):
            product = sp.Mul(*rng.sample(SYMBOLS, rng.randint(1, 3)))
            number = rng.choice(NUMBERS + [None, None])
            terms.append(product if number is None else number * product)
        if rng.random() < 0.4:
            terms.append(rng.choice(NUMBERS))
        if rng.random() < 0.2:
            terms.append(rng.choice(NUMBERS))  # two numbers: SymPy adds them
        yield terms, rng.choice(NUMBERS)


def _same(got, want) -> bool:
    return type(got) is type(want) and got == want and got.args == want.args


def test_a_number_times_a_sum_is_sympys_distributed_sum():
    for terms, number in _sums(2000):
        add = sp.Add(*terms)
        assert _same(mul(number, add), number * add), (number, add)
        assert _same(mul(add, number), add * number), (number, add)


def test_a_sum_of_monomials_is_sympys_sum():
    for terms, _ in _sums(2000, seed=2):
        assert _same(total(terms), sp.Add(*terms)), terms


def _monomials(count: int, seed: int = 3):
    rng = random.Random(seed)
    for _ in range(count):
        product = sp.Mul(*rng.sample(SYMBOLS, rng.randint(1, 3)))
        number = rng.choice(NUMBERS + [None, None])
        yield product if number is None else number * product


def test_negations_and_cross_products_are_sympys():
    for terms, number in _sums(1000, seed=4):
        add = sp.Add(*terms)
        assert _same(negated(add), -add), add
    monomials = list(_monomials(3000))
    for m in monomials:
        assert _same(negated(m), -m), m
    rng = random.Random(5)
    for _ in range(1000):
        a = [rng.choice(monomials + [sp.S.Zero, 0, 1]) for _ in range(3)]
        b = [rng.choice(monomials + [sp.S.Zero, 0]) for _ in range(3)]
        want_all = (mul(a[1], b[2]) - mul(a[2], b[1]), mul(a[2], b[0]) - mul(a[0], b[2]),
                    mul(a[0], b[1]) - mul(a[1], b[0]))  # the former cross product
        for got, want in zip(cross(a, b), want_all):
            assert type(got) is type(want) and got == want and getattr(got, "args", ()) == \
                getattr(want, "args", ()), (a, b)
