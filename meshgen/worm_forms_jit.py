"""Compiled H(r) of the ZN / ZK / ZC table (meshgen.worm_forms.FormTable) for the contact kernel.

The kernel's scalars P carry the table at P[off:off + 2 + N_CHEB] = [r_lo, r_hi, Chebyshev coefficients]
(FormTable.params); `half_thickness` evaluates the series by Clenshaw's recurrence with its derivative, continued
linearly outside [r_lo, r_hi], as FormTable.half_thickness / half_thickness_dr do (tests/test_flank_forms_contact.py).
"""

from __future__ import annotations

import numba

from meshgen.worm_forms import N_CHEB

TABLE_LEN = 2 + N_CHEB  # entries of FormTable.params()


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
