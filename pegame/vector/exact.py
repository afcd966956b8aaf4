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
a square root. :func:`cell_by_product` does the same for the grid cell of a point
(``OccupancyGrid.world_to_cell``'s division by the resolution), from a product. All are
compared with the Python functions in ``tests/test_vector_kernels.py``.
"""

from __future__ import annotations

import math

import numpy as np
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


#: |quotient| (cells) below which cell_by_product's product decides the cell
_QUOTIENT_LIMIT = 2.0**20
#: cell_by_product's |q - trunc(q)| - 1/2 for a product at least 2**-20 from a cell edge
_NEAR_HALF = 0.5 - 2.0**-20


@njit(cache=True, inline="always")
def cell_by_product(u, v, inverse, height, width):
    """(1 + the flat index of the cell (floor(v / res), floor(u / res)) of a grid of
    ``height`` x ``width`` cells, or 0 off the grid; decided) for the grid-frame point
    (u, v) (m), from the products by ``inverse`` = 1 / res.

    When ``decided``, the cell is the one the division picks; else the caller divides.
    With u = 2**-53, fl(1 / res) and the product each err by at most u relatively and
    the division by u, so the two quotients differ by at most 3.01 u |q|, below 4e-10
    cells for |q| < 2**20. A product q whose distance to the nearest whole number,
    1/2 - | |q - trunc(q)| - 1/2 | (exact for |q| < 2**20 but for 2**-55), is more than
    2**-20 therefore lies in the division's cell, and the tests 0 <= q < n (whole n)
    agree, so truncation is the floor where they pass. Not decided: a point within
    2**-20 cells of a cell edge, far off the grid or not finite. Branch-free, so that
    loops of it vectorise; their callers redo a whole loop with the division when any
    point of it is not decided.
    """
    qc, qr = u * inverse, v * inverse
    col, row = np.int64(qc), np.int64(qr)
    decided = (
        (abs(abs(qc - col) - 0.5) < _NEAR_HALF)
        & (abs(abs(qr - row) - 0.5) < _NEAR_HALF)
        & (max(abs(qc), abs(qr)) < _QUOTIENT_LIMIT)
    )
    inside = (qr >= 0.0) & (qr < height) & (qc >= 0.0) & (qc < width)
    return (row * width + col + 1 if inside else 0), decided


@njit(cache=True, inline="always")
def cell_by_division(u, v, res, height, width):
    """:func:`cell_by_product`'s cell from the division itself (``world_to_cell``): a
    quotient in [0, n) is a cell floor(q) in [0, n), and there truncation floors."""
    qc, qr = u / res, v / res
    inside = (qr >= 0.0) & (qr < height) & (qc >= 0.0) & (qc < width)
    return np.int64(qr) * width + np.int64(qc) + 1 if inside else 0
