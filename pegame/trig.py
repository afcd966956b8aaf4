"""Sine and cosine of one angle as a branch-free polynomial, for loops that numba vectorises.

libm's sin and cos branch on the argument's size, so a numba loop that calls them runs
one angle at a time (about 9 ns per sin-cos pair here). :func:`sin_cos` reduces the
angle by pi/2 with Cody and Waite's two-part constant and evaluates fdlibm's minimax
polynomials for sin and cos on [-pi/4, pi/4] (the coefficients of fdlibm's
``__kernel_sin`` and ``__kernel_cos``, which it uses for ``sin`` and ``cos``), then picks
and signs them by the quadrant with arithmetic instead of branches. Inlined into a loop
over an array, LLVM turns it into SIMD code: about four times faster than libm for 2000
angles. For |angle| <= MAX_ANGLE rad the results differ from libm's by at most 2^-52
(one ulp of 1; the tests hold it to that); beyond, the reduction loses accuracy and
callers must use libm.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: rad; the largest |angle| for which :func:`sin_cos` is accurate (2^20 pi/2, as in fdlibm)
MAX_ANGLE = 2.0**20 * math.pi / 2.0

_TWO_OVER_PI = 6.36619772367581382433e-01
_PI_OVER_2_HIGH = 1.57079632673412561417e00  # first 33 bits of pi/2
_PI_OVER_2_LOW = 6.07710050650619224932e-11  # pi/2 - _PI_OVER_2_HIGH

_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11


@njit(cache=True, inline="always")
def sin_cos(angle):
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
