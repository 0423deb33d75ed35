"""The Newmark step of a configuration's layer, the sources, and the layer's values in and out.

A configuration's operators are found by its mask (:func:`find_slot`, the
open-addressing map of :class:`~vtool.solvers.newmark.records.Tables`) and
taken as a :class:`~vtool.solvers.newmark.records.Config` of views
(:func:`configuration`). The predictor and corrector (:func:`predict`,
:func:`corrected`) and the sources' harmonics (:func:`harmonics`) are inline
helpers shared by every step: :func:`layer_step` here and the quiet loop
(:mod:`~vtool.solvers.newmark.kernel.quiet`).
"""

from __future__ import annotations

import math

import numpy as np

from vtool.jit import jit, jit_inline
from vtool.solvers.newmark import layout
from vtool.solvers.newmark.kernel.algebra import cholesky_solve, factor_effective, operator_product
from vtool.solvers.newmark.kernel.forces import hertz_correction, hertz_force, overlap_and_rate
from vtool.solvers.newmark.records import Config

# how a step solves S z̈ = rhs (layer_step's ``which``): stored inverses of the standard and refined
# steps, or a Cholesky factor. np.int64 values, not int literals: numba compiles a function once per
# literal argument value.
STANDARD, REFINED, CHOLESKY = np.int64(0), np.int64(1), np.int64(2)


@jit_inline
def find_slot(index, mask):
    """The slot of configuration ``mask`` in the tables, or -1 when it is not built (see
    :func:`vtool.solvers.newmark.records.mask_hash`: the same first probe, then the next entries)."""
    capacity = index.shape[0]
    h = (mask ^ (mask >> 7) ^ (mask >> 17)) & (capacity - 1)
    for _ in range(capacity):
        key = index[h, 0]
        if key == mask:
            return index[h, 1]
        if key < 0:
            return -1
        h = (h + 1) & (capacity - 1)
    return -1


@jit_inline
def configuration(T, mask, slot):
    """Configuration ``mask``'s operators (views of its slot)."""
    return Config(mask, T.ci[slot], T.cm[slot], T.cp[slot], T.mk[slot], T.mon[slot])


@jit_inline
def harmonics(series, omega, c1, s1, src):
    """src[3s : 3s + 3] = (x, v, a) of every source s (the row ``series[s]``: its constant, then the
    cosine and the sine coefficients, see :func:`~vtool.solvers.newmark.layout.series_table`) at the
    angle whose cos and sin are c1, s1 (harmonics by angle addition)."""
    ns, nh = series.shape[0], (series.shape[1] - 1) // 2
    for s in range(ns):
        src[3 * s] = series[s, 0]
        src[3 * s + 1] = 0.0
        src[3 * s + 2] = 0.0
    ck = 1.0
    sk = 0.0
    for k in range(nh):
        ck, sk = ck * c1 - sk * s1, sk * c1 + ck * s1  # cos, sin of (k + 1) omega t
        wk = (k + 1) * omega
        for s in range(ns):
            a = series[s, 1 + k]
            b = series[s, 1 + nh + k]
            src[3 * s] += a * ck + b * sk
            src[3 * s + 1] += wk * (b * ck - a * sk)
            src[3 * s + 2] -= wk * wk * (a * ck + b * sk)


@jit
def sources(series, omega, t, src):
    """src = (x, v, a) of every source at t (the problem's ``series`` table at cam speed ``omega``): on
    the arrays it reads, not the record (a call passes, and numba's Python wrapper unboxes, one array)."""
    harmonics(series, omega, math.cos(omega * t), math.sin(omega * t), src)


@jit_inline
def gather(C, n, S, y):
    """The layer state y of the full state (S.x, S.v, S.a)."""
    for j in range(C.ci[layout.CI_M]):
        i = C.ci[layout.CI_HEAD + j]
        y[layout.Z, j] = S.x[i]
        y[layout.ZD, j] = S.v[i]
        y[layout.ZDD, j] = S.a[i]


@jit_inline
def scatter(C, n, y, S):
    """The full state (S.x, S.v, S.a) of the layer state y."""
    for i in range(n):
        j = C.ci[layout.CI_HEAD + n + i]
        S.x[i] = y[layout.Z, j]
        S.v[i] = y[layout.ZD, j]
        S.a[i] = y[layout.ZDD, j]


@jit_inline
def prescribed(ci, n, src, z, zd, zdd):
    """The prescribed entries of (z, ż, z̈) (z indices nf..m-1 of the configuration whose integer row
    is ci) from their sources."""
    for j in range(ci[layout.CI_NF], ci[layout.CI_M]):
        s = ci[layout.CI_HEAD + 2 * n + j]
        z[j] = src[3 * s]
        zd[j] = src[3 * s + 1]
        zdd[j] = src[3 * s + 2]


@jit_inline
def predict(m, h, beta, gamma, z, zd, zdd, z1, zd1):
    """Newmark's predictor of the first m entries: z̃ = z + h ż + h²(1/2 - beta) z̈ into z1,
    ż̃ = ż + h(1 - gamma) z̈ into ż1."""
    hx = h * h * (0.5 - beta)
    hv = h * (1.0 - gamma)
    for j in range(m):
        z1[j] = z[j] + h * zd[j] + hx * zdd[j]
        zd1[j] = zd[j] + hv * zdd[j]


@jit_inline
def corrected(a, z, zd, bx, gv):
    """Newmark's corrector of one coordinate: (z + bx a, ż + gv a) from the predicted z, ż and the
    new acceleration a (bx = beta h², gv = gamma h). Scalars only: the quiet loop calls it at every
    step, and an inline helper handed arrays there left a reference count taken and dropped at every
    step, an opaque call that also spilled the loop's registers (2-3 % of a quiet step)."""
    return z + bx * a, zd + gv * a


@jit_inline
def correct(nf, h, beta, gamma, acc, z1, zd1, zdd1):
    """Newmark's corrector of the nf free coordinates (:func:`corrected`): the accelerations ``acc``
    into z̈1, the predicted z1, ż1 corrected in place."""
    bx = beta * h * h
    gv = gamma * h
    for f in range(nf):
        a = acc[f]
        zdd1[f] = a
        z1[f], zd1[f] = corrected(a, z1[f], zd1[f], bx, gv)


@jit_inline
def free_rhs(C, src, y, rhs):
    """rhs_F = -C_FF ż_F - K_FF z_F - (M_FP z̈_P + C_FP ż_P + K_FP z_P) - S_F src: the thesis' ΔP on the
    right, and the sources' pull through closed compliant contacts (``layout.CP_RAW``)."""
    operator_product(C.cp, C.ci, layout.CP_RAW, C.ci[layout.CI_NF], C.ci[layout.CI_SRC], src, y[layout.Z],
                     y[layout.ZD], y[layout.ZDD], rhs)


@jit
def layer_step(prob, C, W, h, which, hertz):
    """One Newmark step of length h from layer state W.y[Y_NOW] into W.y[Y_END], the sources at t + h
    in W.src[SRC_END].

    ``which``: STANDARD the stored S⁻¹ of the standard step (as one product with G = S⁻¹R),
    REFINED of the refined step, CHOLESKY S(h) factored here by Cholesky into W.L (every step of another
    length: event location's trials, the step to an event, the return to the step grid). Closed Hertz
    contacts are added by Newton iteration (:func:`~vtool.solvers.newmark.kernel.forces.hertz_correction`).
    """
    beta, gamma = prob.fp[layout.FP_BETA], prob.fp[layout.FP_GAMMA]
    ci, y, y1, src1 = C.ci, W.y[layout.Y_NOW], W.y[layout.Y_END], W.src[layout.SRC_END]
    nf = ci[layout.CI_NF]
    if which == CHOLESKY:
        factor_effective(C.cm, nf, beta, gamma, h, W.L)
    predict(ci[layout.CI_M], h, beta, gamma, y[layout.Z], y[layout.ZD], y[layout.ZDD], y1[layout.Z], y1[layout.ZD])
    prescribed(ci, prob.ip[layout.IP_N], src1, y1[layout.Z], y1[layout.ZD], y1[layout.ZDD])
    # CHOLESKY: ΔP (free_rhs's product) into the system's RHS row, then solved; else z̈_F = S⁻¹ ΔP as one product
    # with the stored G = S⁻¹R into its SOL row. One product for both (each row sums in the same order either way).
    plane = layout.CP_RAW if which == CHOLESKY else (layout.CP_STD if which == STANDARD else layout.CP_FINE)
    rhs, sol = W.system[layout.RHS], W.system[layout.SOL]
    out = rhs if which == CHOLESKY else sol
    operator_product(C.cp, ci, plane, nf, ci[layout.CI_SRC], src1, y1[layout.Z], y1[layout.ZD], y1[layout.ZDD], out)
    if which == CHOLESKY:
        cholesky_solve(nf, W.L, rhs, sol)
    correct(nf, h, beta, gamma, sol, y1[layout.Z], y1[layout.ZD], y1[layout.ZDD])
    if hertz is not None:
        if C.ci[layout.CI_HERTZ]:
            hertz_correction(prob, C, W, h, which)


@jit_inline
def consistent_acceleration(prob, C, src, y, rhs, hertz):
    """Free accelerations of configuration C from its equations of motion (prescribed set from src)."""
    prescribed(C.ci, prob.ip[layout.IP_N], src, y[layout.Z], y[layout.ZD], y[layout.ZDD])
    free_rhs(C, src, y, rhs)
    nf = C.ci[layout.CI_NF]
    if hertz is not None:
        if C.ci[layout.CI_HERTZ]:  # the Hertz forces of the present overlaps, on the free rows (w = -mon row)
            for k in range(prob.cl.shape[0]):
                if C.mk[k, layout.MK_KIND] == layout.MK_OVERLAP and prob.cl[k, layout.CL_SOFT] == layout.SOFT_HERTZ:
                    delta, rate = overlap_and_rate(prob, C, k, y, src)
                    force = hertz_force(prob.clf, k, delta, rate)[0]
                    for f in range(nf):
                        rhs[f] -= C.mon[k, f] * force
    for f in range(nf):
        s = 0.0
        for g in range(nf):
            s += C.cm[layout.CM_MINVFF, f, g] * rhs[g]
        y[layout.ZDD, f] = s


@jit_inline
def interpolate(nf, s_out, h, z, zd, zdd, zdd1, out):
    """The free coordinates at s_out into a step of length h from (z, ż, z̈) whose end acceleration is
    z̈1, into the layer state ``out``: the linear-acceleration interpolant (exact for beta = 1/6;
    thesis eqs. B.3-B.5)."""
    zo, zdo, zddo = out[layout.Z], out[layout.ZD], out[layout.ZDD]
    r = s_out / h
    for j in range(nf):
        da = zdd1[j] - zdd[j]
        zddo[j] = zdd[j] + da * r
        zdo[j] = zd[j] + zdd[j] * s_out + da * s_out * r / 2.0
        zo[j] = z[j] + zd[j] * s_out + zdd[j] * s_out * s_out / 2.0 + da * s_out * s_out * r / 6.0
