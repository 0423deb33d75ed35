"""The kernel's linear algebra: the step operators' product, Cholesky, the stored inverses, dense solves."""

from __future__ import annotations

import math

from vtool.jit import jit, jit_inline
from vtool.solvers.newmark import layout


@jit_inline
def apply_operator(cp, ci, plane, nrows, coupled, src, z, zd, zdd, out):
    """out[:nrows] = -R·(ż_F, z_F, (z̈, ż, z)_P, src) for step operator R = cp[plane] of the configuration
    whose integer row is ci (see ``layout.CP_RAW``) and layer state (z, ż, z̈): the nf free rows, and in
    a step plane the force rows after them.

    Column by column: cp holds Rᵀ, each column's coefficients on the free rows side by side, so that
    every row's running sum takes the column's term in one pass over the rows, a loop the compiler runs
    on vectors of rows; each row is still summed in column order. The rows run on to a multiple of four
    where out and cp have room (nobody reads the rows past nrows). Plain arrays, no records: in the
    quiet loop a record's field read is a reference count taken and dropped at every step."""
    nf = ci[layout.CI_NF]
    m = ci[layout.CI_M]
    rows = min((nrows + 3) // 4 * 4, out.shape[0], cp.shape[3])
    g0 = 0
    if nf > 0:  # the first column's terms from 0.0 (the same bits as zeroing first; a zeroing loop alone
        a = zd[0]  # became a call to memset at every quiet step, which spilled the loop's registers)
        b = z[0]
        for f in range(rows):
            out[f] = 0.0 - (cp[plane, layout.PART_C, 0, f] * a + cp[plane, layout.PART_K, 0, f] * b)
        g0 = 1
    else:
        for f in range(rows):
            out[f] = 0.0
    for g in range(g0, nf):
        a = zd[g]
        b = z[g]
        for f in range(rows):
            out[f] -= cp[plane, layout.PART_C, g, f] * a + cp[plane, layout.PART_K, g, f] * b
    for p in range(m - nf):
        j = nf + p
        a = zdd[j]
        b = zd[j]
        d = z[j]
        for f in range(rows):
            out[f] -= (cp[plane, layout.PART_P, 3 * p, f] * a + cp[plane, layout.PART_P, 3 * p + 1, f] * b
                       + cp[plane, layout.PART_P, 3 * p + 2, f] * d)
    if coupled:
        for j in range(src.shape[0]):
            a = src[j]
            for f in range(rows):
                out[f] -= cp[plane, layout.PART_S, j, f] * a


@jit
def operator_product(cp, ci, plane, nrows, coupled, src, z, zd, zdd, out):
    """:func:`apply_operator` as a call, for the event path's steps (one compiled copy, not one per caller)."""
    apply_operator(cp, ci, plane, nrows, coupled, src, z, zd, zdd, out)


@jit_inline
def factor_effective(cm, nf, beta, gamma, h, L):
    """Cholesky factor (lower, in place in L) of S = M_FF + gamma h C_FF + beta h² K_FF (the nf free
    rows of a configuration's matrices cm)."""
    for f in range(nf):
        for g in range(f + 1):
            s = cm[layout.CM_MFF, f, g] + gamma * h * cm[layout.CM_CFF, f, g] + beta * h * h * cm[layout.CM_KFF, f, g]
            for k in range(g):
                s -= L[f, k] * L[g, k]
            if f == g:
                L[f, f] = math.sqrt(s) if s > 0.0 else 1e-300
            else:
                L[f, g] = s / L[g, g]


@jit_inline
def cholesky_solve(nf, L, rhs, out):
    for f in range(nf):
        s = rhs[f]
        for k in range(f):
            s -= L[f, k] * out[k]
        out[f] = s / L[f, f]
    for f in range(nf - 1, -1, -1):
        s = out[f]
        for k in range(f + 1, nf):
            s -= L[k, f] * out[k]
        out[f] = s / L[f, f]


@jit
def effective_solve(C, which, L, b, out):
    """out = S⁻¹ b: the stored inverse of the standard (``which`` 0) or refined (1) step, or the
    Cholesky factor in L (2)."""
    nf = C.ci[layout.CI_NF]
    if which == 2:
        cholesky_solve(nf, L, b, out)
        return
    slot = layout.CM_SINV if which == 0 else layout.CM_SINVF
    for f in range(nf):
        acc = 0.0
        for g in range(nf):
            acc += C.cm[slot, f, g] * b[g]
        out[f] = acc


@jit
def solve_dense(A, b, out, na):
    """out[:na] = A[:na, :na]⁻¹ b[:na] by Gaussian elimination with partial pivoting (A, b overwritten)."""
    for col in range(na):
        pivot = col
        for r in range(col + 1, na):
            if abs(A[r, col]) > abs(A[pivot, col]):
                pivot = r
        if pivot != col:
            for q in range(na):
                A[col, q], A[pivot, q] = A[pivot, q], A[col, q]
            b[col], b[pivot] = b[pivot], b[col]
        d = A[col, col] if A[col, col] != 0.0 else 1e-300
        for r in range(col + 1, na):
            f = A[r, col] / d
            for q in range(col, na):
                A[r, q] -= f * A[col, q]
            b[r] -= f * b[col]
    for r in range(na - 1, -1, -1):
        s = b[r]
        for q in range(r + 1, na):
            s -= A[r, q] * out[q]
        d = A[r, r] if A[r, r] != 0.0 else 1e-300
        out[r] = s / d
