"""The worm's H(r) compiled, its one evaluation: the axial half-thickness of the thread and its derivative dH/dr at
radius r (meshgen.worm's equations (1), (2): ZI the involute helicoid, ZA straight; ZN, ZK, ZC the Chebyshev table of
meshgen.worm_forms.FormTable), on the worm's scalars P (meshgen.worm.worm_params). The contact kernel's worm gap
(wormsim.tooth.gap) calls `thread_half_thickness`, FormTable (and so meshgen.worm.half_thickness for ZN, ZK, ZC) the
table's `half_thickness`; ZA's and ZI's closed forms are written once here (za_half_thickness, zi_half_thickness) and
meshgen.worm evaluates the same text on numpy arrays.

The kernel's scalars P carry the table at P[TABLE_AT:TABLE_AT + 2 + N_CHEB] = [r_lo, r_hi, Chebyshev coefficients]
(FormTable.params); `half_thickness` evaluates the series by Clenshaw's recurrence with its derivative, continued
linearly outside [r_lo, r_hi] (tests/tooth/test_gap.py).
"""

from __future__ import annotations

import numba
import numpy as np

N_CHEB = 40  # Chebyshev terms of the H(r) table
TABLE_LEN = 2 + N_CHEB  # entries of FormTable.params()
# the entries of P that H(r) reads (meshgen.worm.worm_params: the whole layout)
P_P, P_PX, P_FORM, P_RB, P_TAN_ALPHA_X, P_T1, P_R1 = 0, 1, 5, 6, 7, 8, 9
TABLE_AT = 13  # where the table starts in P
ZA, ZI, TABLE = 0.0, 1.0, 2.0  # P[P_FORM]


@numba.njit(cache=True, inline="always")
def half_thickness(r, P, off):
    """(H(r), dH/dr) of the table at P[off:off + TABLE_LEN]."""
    lo, hi = P[off], P[off + 1]
    rc = min(max(r, lo), hi)
    sc = 2.0 / (hi - lo)
    x = (2.0 * rc - lo - hi) / (hi - lo)
    # Clenshaw for sum c_k T_k(x) and its derivative (b_k recurrences differentiated)
    b1 = 0.0
    b2 = 0.0
    d1 = 0.0
    d2 = 0.0
    for k in range(N_CHEB - 1, 0, -1):
        ck = P[off + 2 + k]
        b0 = 2.0 * x * b1 - b2 + ck
        d0 = 2.0 * b1 + 2.0 * x * d1 - d2
        b2, b1 = b1, b0
        d2, d1 = d1, d0
    H = x * b1 - b2 + P[off + 2]
    dH = (b1 + x * d1 - d2) * sc
    return H + (r - rc) * dH, dH


def za_half_thickness(r, p_x, r1, tan_alpha_x):
    """ZA's H(r), equation (1): straight flanks at the axial pressure angle. Written once: meshgen.worm calls it on
    numpy arrays, the kernel compiled (thread_half_thickness)."""
    return p_x / 4 - (r - r1) * tan_alpha_x


def zi_t(r, r_b):
    """ZI's involute parameter t = sqrt(r^2 / r_b^2 - 1), 0 below the base radius (numpy arrays or compiled)."""
    return np.sqrt(np.maximum(r * r / (r_b * r_b) - 1.0, 0.0))


def zi_half_thickness(t, ap, p_x, t1_term):
    """ZI's H(r), equation (2), at t = zi_t(r): p_x / 4 - |p| ((t - atan t) - (t1 - atan t1)), t1_term = t1 - atan t1.
    Written once: meshgen.worm calls it on numpy arrays (numpy's arctan), the kernel compiled (the C library's atan;
    the two differ by an ulp at some radii, as they did before the two paths shared this text)."""
    return p_x / 4 - ap * ((t - np.arctan(t)) - t1_term)


_za = numba.njit(cache=True, inline="always")(za_half_thickness)
_zi_t = numba.njit(cache=True, inline="always")(zi_t)
_zi = numba.njit(cache=True, inline="always")(zi_half_thickness)


@numba.njit(cache=True, inline="always")
def thread_half_thickness(r, P):
    """(H(r), dH/dr) of the worm (module docstring): ZI equation (2) with t = sqrt(r^2 / r_b^2 - 1) (0 below r_b),
    ZA straight, ZN / ZK / ZC the table."""
    if P[P_FORM] > 1.5:
        return half_thickness(r, P, TABLE_AT)
    if P[P_FORM] > 0.5:
        t = _zi_t(r, P[P_RB])
        ap = abs(P[P_P])
        return _zi(t, ap, P[P_PX], P[P_T1]), -ap * t / r
    return _za(r, P[P_PX], P[P_R1], P[P_TAN_ALPHA_X]), -P[P_TAN_ALPHA_X]


@numba.njit(cache=True)
def table_many(r, T, H, dH):
    """half_thickness of the table T (FormTable.params) over the flat array r into H and dH."""
    for i in range(r.shape[0]):
        H[i], dH[i] = half_thickness(r[i], T, 0)
