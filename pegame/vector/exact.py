"""Python's own float functions in numba, bit for bit, for kernels that must play the
same game as the plain-Python code.

Two functions of the single game's Python code round differently from what numba
compiles for the same expression:

- ``math.hypot`` (CPython >= 3.10) is not the C library's ``hypot``, which numba calls:
  CPython scales the coordinates by a power of two, squares them exactly (Dekker's
  product), sums with the error terms kept and applies one differential correction
  (``vector_norm`` in CPython's ``Modules/mathmodule.c``; Borges, "An Improved Algorithm
  for hypot(a, b)", 2019). The two differ in the last bit for about one pair in 200.
  :func:`hypot` is CPython's algorithm for two coordinates.
- :func:`pegame.types.wrap_angle` is the IEEE remainder by 2 pi, which numba does not
  compile. :func:`wrap_angle` computes it exactly for the angles a game produces (|angle|
  up to 3 pi, where the remainder is one exact subtraction, Sterbenz's lemma) and falls
  back to Python's floored modulo and one correction beyond.

:func:`ceil_of_hypot` and :func:`hypot_within` give what a kernel does with the exact
hypot (a sample count, a range test) from the plain sqrt(x^2 + y^2), and take the exact
one only when that is within its error bound of the answer's edge: most calls then cost
a square root. All are compared with the Python functions in
``tests/test_vector_kernels.py``.
"""

from __future__ import annotations

import math

from numba import njit

_SPLIT = 134217729.0  # 2^27 + 1, Veltkamp's splitting constant for float64


@njit(cache=True, inline="always")
def _square(x):
    """(hi, lo) with hi + lo = x * x exactly (Dekker's product, no FMA)."""
    hi = x * x
    t = _SPLIT * x
    xh = t - (t - x)
    xl = x - xh
    lo = ((xh * xh - hi) + 2.0 * xh * xl) + xl * xl
    return hi, lo


@njit(cache=True, inline="always")
def _product(x, y):
    """(hi, lo) with hi + lo = x * y exactly (Dekker's product, no FMA)."""
    hi = x * y
    t = _SPLIT * x
    xh = t - (t - x)
    xl = x - xh
    t = _SPLIT * y
    yh = t - (t - y)
    yl = y - yh
    lo = ((xh * yh - hi) + xh * yl + xl * yh) + xl * yl
    return hi, lo


@njit(cache=True)
def hypot(x, y):
    """``math.hypot(x, y)`` of CPython 3.10+, bit for bit (module docstring), unless the
    larger magnitude is subnormal (below 2.2e-308 m: no game has such lengths)."""
    x, y = abs(x), abs(y)
    if math.isinf(x) or math.isinf(y):
        return math.inf
    if math.isnan(x) or math.isnan(y):
        return math.nan
    biggest = max(x, y)
    if biggest == 0.0:
        return biggest
    exponent = math.frexp(biggest)[1]
    if exponent < -1021:  # subnormal: not in any game; the C library's hypot
        return math.hypot(x, y)
    scale = math.ldexp(1.0, -exponent)
    csum, frac1, frac2 = 1.0, 0.0, 0.0
    for value in (x, y):
        value *= scale
        hi, lo = _square(value)
        total = csum + hi  # dl_fast_sum: |csum| >= |hi|
        frac2 += hi - (total - csum)
        csum = total
        frac1 += lo
    h = math.sqrt(csum - 1.0 + (frac1 + frac2))
    hi, lo = _product(-h, h)
    total = csum + hi
    frac2 += hi - (total - csum)
    csum = total
    frac1 += lo
    correction = csum - 1.0 + (frac1 + frac2)
    h += correction / (2.0 * h)
    return h / scale


@njit(cache=True)
def wrap_angle(angle):
    """:func:`pegame.types.wrap_angle` (rad, onto (-pi, pi]), bit for bit."""
    period = 2.0 * math.pi
    if abs(angle) <= math.pi:
        wrapped = angle  # a tie at +-pi keeps the even quotient 0
    elif math.pi < angle <= 3.0 * math.pi:
        wrapped = angle - period  # exact: pi <= angle <= 2 period (Sterbenz)
    elif -3.0 * math.pi <= angle < -math.pi:
        wrapped = angle + period
    else:
        wrapped = angle % period  # floored, exact; then onto [-pi, pi]
        if wrapped > math.pi:
            wrapped -= period
    return math.pi if wrapped == -math.pi else wrapped


#: a bound, relative, on |sqrt(x * x + y * y) - hypot(x, y)| (a few ulps, with margin)
_NAIVE_ERROR = 1e-12


@njit(cache=True, inline="always")
def _margin(value):
    return _NAIVE_ERROR * (abs(value) + 1.0)


@njit(cache=True)
def ceil_of_hypot(x, y, res):
    """``math.ceil(2 * hypot(x, y) / res)`` (res > 0) of Python's hypot (the grid
    simulator's sample count), from the plain sqrt(x * x + y * y) unless a whole number
    lies within its error bound."""
    naive = 2 * math.sqrt(x * x + y * y) / res
    whole = math.ceil(naive)
    if whole - naive > _margin(naive) and naive - (whole - 1) > _margin(naive):
        return whole
    return math.ceil(2 * hypot(x, y) / res)


@njit(cache=True)
def hypot_within(x, y, low, high):
    """``low <= hypot(x, y) <= high`` of Python's hypot, from the plain sqrt(x * x + y * y)
    unless it lies within its error bound of low or high."""
    naive = math.sqrt(x * x + y * y)
    margin = _margin(naive)
    if abs(naive - low) > margin and abs(naive - high) > margin:
        return low <= naive <= high
    return low <= hypot(x, y) <= high
