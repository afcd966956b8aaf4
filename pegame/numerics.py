"""pegame's numerics for numba kernels, in one module: functions that give the same bits
on every CPU (a vectorisable sine-cosine, the exponential), Python's own float functions
bit for bit (hypot, the angle wrap), and what kernels decide from them (a sample count,
a range test, a grid cell).

Numba compiles these without fastmath, so LLVM neither reorders nor fuses their floating-
point operations and the result does not depend on the CPU's vector width or on FMA;
numpy's own exp, log, arctan2 and tanh dispatch to AVX2 or AVX-512 loops that differ in
the last ulp from the generic ones (``tests/test_determinism.py``), and glibc's exp has an
FMA variant, so neither is used where it decides a game.

**Sine and cosine** of one angle as a branch-free polynomial, for loops that numba
vectorises. libm's sin and cos branch on the argument's size, so a numba loop that calls
them runs one angle at a time (about 9 ns per sin-cos pair here). :func:`sin_cos` reduces
the angle by pi/2 with Cody and Waite's two-part constant and evaluates fdlibm's minimax
polynomials for sin and cos on [-pi/4, pi/4] (the coefficients of fdlibm's
``__kernel_sin`` and ``__kernel_cos``, which it uses for ``sin`` and ``cos``), then picks
and signs them by the quadrant with arithmetic instead of branches. Inlined into a loop
over an array, LLVM turns it into SIMD code: about four times faster than libm for 2000
angles. For |angle| <= MAX_ANGLE rad the results differ from libm's by at most 2^-52
(one ulp of 1; the tests hold it to that); beyond, the reduction loses accuracy and
callers must use libm.

**The exponential** :func:`exps` is fdlibm's ``__ieee754_exp`` (the reduction x = k ln 2 +
r with a two-part ln 2, and its degree-5 minimax polynomial for r / (exp(r) - 1)), less
than one ulp from the exact value, for the arguments that give a normal result.

**Python's hypot**: ``math.hypot`` (CPython >= 3.10) is not the C library's ``hypot``,
which numba calls: CPython scales the coordinates by a power of two, squares them exactly
(Dekker's product), sums with the error terms kept and applies one differential
correction (``vector_norm`` in CPython's ``Modules/mathmodule.c``; Borges, "An Improved
Algorithm for hypot(a, b)", 2019). The two differ in the last bit for about one pair in
200. :func:`hypot` is CPython's algorithm for two coordinates. :func:`ceil_of_hypot` and
:func:`hypot_within` give what a kernel does with the exact hypot (a sample count, a range
test) from the plain sqrt(x^2 + y^2), and take the exact one only when that is within its
error bound of the answer's edge: most calls then cost a square root.
:func:`cell_by_product` does the same for the grid cell of a point
(``OccupancyGrid.world_to_cell``'s division by the resolution), from a product.

**The angle wrap** onto (-pi, pi]. The games' wrap is the IEEE remainder by 2 pi,
:func:`pegame.types.wrap_angle` for Python floats (``math.remainder``, 73 ns a call; the
numba function below called from Python takes 113 ns, and importing numba would add 0.2 s
to ``import pegame.api``, so the scalar form stays there); :func:`wrap_angle` is the same
in numba code, bit for bit (numba does not compile ``math.remainder``): exact for the
angles a game produces (|angle| up to 3 pi, where the remainder is one exact subtraction,
Sterbenz's lemma), Python's floored modulo and one correction beyond. The particle
filter's wrap is older and rounds differently, by a few ulps of pi: numpy's ``pi - ((pi -
angle) mod 2 pi)`` (:func:`wrap_angles_reference`), with :func:`wrap_angle_kernel` that
for one angle in numba code, bit for bit and mostly without the slow fmod, and
:func:`wrap_angles` that kernel as a numpy ufunc. (The rounded modulo can reach 2 pi, so
an angle within an ulp above an odd multiple of pi wraps to -pi.) It stays apart because
the remainder in its place changes the particles' bits (the belief digest of
``pegame.testing.reference_games``), that is the games.

All are compared with the Python and numpy functions in ``tests/test_numerics.py``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, vectorize

#: rad; the largest |angle| for which :func:`sin_cos` is accurate (2^20 pi/2, as in fdlibm)
MAX_ANGLE = 2.0**20 * math.pi / 2.0

_TWO_OVER_PI = 6.36619772367581382433e-01
_PI_OVER_2_HIGH = 1.57079632673412561417e00  # first 33 bits of pi/2
_PI_OVER_2_LOW = 6.07710050650619224932e-11  # pi/2 - _PI_OVER_2_HIGH

_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11


_LN2_HIGH = 6.93147180369123816490e-01  # first 32 bits of ln 2
_LN2_LOW = 1.90821492927058770002e-10  # ln 2 - _LN2_HIGH
_INV_LN2 = 1.44269504088896338700e00
_P1, _P2, _P3 = 1.66666666666666019037e-01, -2.77777777770155933842e-03, 6.61375632143793436117e-05
_P4, _P5 = -1.65339022054652515390e-06, 4.13813679705723846039e-08
#: exp(x) is below the smallest normal float (2.2e-308) for x below this; exps gives 0
EXP_NORMAL_MIN = -708.0
#: the largest argument of exps (the scale 2^k must stay a normal float)
EXP_MAX = 709.0


@njit(cache=True, error_model="numpy")  # no zero-division branch (2 - c > 0): vectorised
def exps(x: np.ndarray) -> np.ndarray:
    """exp of every element of the float array ``x`` (fdlibm's algorithm, < 1 ulp), each
    at most EXP_MAX; 0 where it is below EXP_NORMAL_MIN (also -inf), where the exact value
    would be subnormal or below. Branch-free, so numba vectorises it."""
    n = x.size
    out = np.empty(n)
    bits = np.empty(n, dtype=np.int64)
    for i in range(n):
        low = x[i] < EXP_NORMAL_MIN
        xi = 0.0 if low else x[i]  # keeps the reduction finite; the select below gives 0
        k = np.floor(xi * _INV_LN2 + 0.5)  # a float: math.floor's int stops vectorisation
        hi = xi - k * _LN2_HIGH
        lo = k * _LN2_LOW
        r = hi - lo
        t = r * r
        c = r - t * (_P1 + t * (_P2 + t * (_P3 + t * (_P4 + t * _P5))))
        out[i] = 0.0 if low else 1.0 - ((lo - (r * c) / (2.0 - c)) - hi)
        bits[i] = (np.int64(k) + 1023) << 52  # the float 2^k
    scale = bits.view(np.float64)
    for i in range(n):
        out[i] *= scale[i]  # exact: a power of two, and the product stays normal
    return out


@njit(cache=True, inline="always")
def sin_cos(angle: float) -> tuple[float, float]:
    """(sin, cos) of ``angle`` (rad), |angle| <= MAX_ANGLE, within 2^-52 of libm's."""
    quadrant = math.floor(angle * _TWO_OVER_PI + 0.5)
    r = (angle - quadrant * _PI_OVER_2_HIGH) - quadrant * _PI_OVER_2_LOW
    z = r * r
    s = r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    c = 1.0 - 0.5 * z + z * z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))
    q = np.int64(quadrant)
    swap = (q & 1) == 1
    # sin is (s, c, -s, -c) and cos (c, -s, -c, s) in quadrants 0 to 3.
    sin_sign = 1.0 - 2.0 * ((q >> 1) & 1)
    cos_sign = 1.0 - 2.0 * (((q + 1) >> 1) & 1)
    return (c if swap else s) * sin_sign, (s if swap else c) * cos_sign


def wrap_angles_reference(angles: np.ndarray | float) -> np.ndarray | float:
    """Angles (rad, array or scalar) wrapped to (-pi, pi] (module docstring): ``pi - ((pi -
    angles) mod 2 pi)`` with numpy's floored modulo; the definition that
    :func:`wrap_angle_kernel` follows."""
    return np.pi - np.mod(np.pi - angles, 2.0 * np.pi)


@njit(cache=True)
def wrap_angle_kernel(angle: float) -> float:
    """:func:`wrap_angles_reference` of one angle (rad), bit for bit, mostly without fmod
    (slow in libm).

    numpy's remainder r = (pi - angle) mod 2 pi is fmod(y, 2 pi) for y = pi - angle, plus
    2 pi when that is negative (+0 when it is zero). For -2 pi < y < 4 pi the fmod is y
    or y - 2 pi, exact by Sterbenz's lemma, and the addition is the same float operation
    numpy does; other angles take the general remainder.
    """
    y = math.pi - angle
    period = 2.0 * math.pi
    if 0.0 < y < period:
        remainder = y
    elif period <= y < 2.0 * period:
        remainder = y - period
    elif -period < y < 0.0:
        remainder = y + period
    else:
        remainder = y % period
    return math.pi - remainder


@vectorize(["float64(float64)"], cache=True)
def wrap_angles(angles: float) -> float:
    """Angles (rad, float64 array or scalar) wrapped to (-pi, pi]: :func:`wrap_angle_kernel`
    elementwise, so bit for bit :func:`wrap_angles_reference` (and about twice as fast)."""
    return wrap_angle_kernel(angles)


_SPLIT = 134217729.0  # 2^27 + 1, Veltkamp's splitting constant for float64


@njit(cache=True, inline="always")
def _square(x: float) -> tuple[float, float]:
    """(hi, lo) with hi + lo = x * x exactly (Dekker's product, no FMA)."""
    hi = x * x
    t = _SPLIT * x
    xh = t - (t - x)
    xl = x - xh
    lo = ((xh * xh - hi) + 2.0 * xh * xl) + xl * xl
    return hi, lo


@njit(cache=True, inline="always")
def _product(x: float, y: float) -> tuple[float, float]:
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
def hypot(x: float, y: float) -> float:
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
def wrap_angle(angle: float) -> float:
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
    if wrapped == 0.0:
        wrapped = math.copysign(0.0, angle)  # the remainder's zero has the angle's sign
    return math.pi if wrapped == -math.pi else wrapped


#: a bound, relative, on |sqrt(x * x + y * y) - hypot(x, y)| (a few ulps, with margin)
_NAIVE_ERROR = 1e-12


@njit(cache=True, inline="always")
def _margin(value: float) -> float:
    return _NAIVE_ERROR * (abs(value) + 1.0)


@njit(cache=True)
def ceil_of_hypot(x: float, y: float, res: float) -> int:
    """``math.ceil(2 * hypot(x, y) / res)`` (res > 0) of Python's hypot (the grid
    simulator's sample count), from the plain sqrt(x * x + y * y) unless a whole number
    lies within its error bound."""
    naive = 2 * math.sqrt(x * x + y * y) / res
    whole = math.ceil(naive)
    if whole - naive > _margin(naive) and naive - (whole - 1) > _margin(naive):
        return whole
    return math.ceil(2 * hypot(x, y) / res)


@njit(cache=True)
def hypot_within(x: float, y: float, low: float, high: float) -> bool:
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
def cell_by_product(
    u: float, v: float, inverse: float, height: int, width: int
) -> tuple[int, bool]:
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
def cell_by_division(u: float, v: float, res: float, height: int, width: int) -> int:
    """:func:`cell_by_product`'s cell from the division itself (``world_to_cell``): a
    quotient in [0, n) is a cell floor(q) in [0, n), and there truncation floors."""
    qc, qr = u / res, v / res
    inside = (qr >= 0.0) & (qr < height) & (qc >= 0.0) & (qc < width)
    return np.int64(qr) * width + np.int64(qc) + 1 if inside else 0
