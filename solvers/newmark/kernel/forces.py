"""Contact forces and monitors: the linear force rows, the Hertz law and its Newton iteration in a step."""

from __future__ import annotations

import numpy as np

from vtool.jit import jit, jit_inline
from vtool.solvers.newmark import layout
from vtool.solvers.newmark.kernel.algebra import effective_solve, solve_dense


@jit
def hertz_force(clf, k, delta, rate):
    """(F, dF/dδ, dF/dδ̇) of Hertz contact k: F = K δⁿ (1 + 3(1 - e)/2 · δ̇/v⁻), never pulling.

    v⁻ is the approach velocity of the contact's closing (Hunt and Crossley
    1975: the damping that gives restitution e at an impact at v⁻)."""
    if delta <= 0.0:
        return 0.0, 0.0, 0.0
    stiffness = clf[k, layout.CLF_HK]
    exponent = clf[k, layout.CLF_HN]
    lam = 1.5 * (1.0 - clf[k, layout.CLF_E]) / clf[k, layout.CLF_HV]
    power = stiffness * delta**exponent
    force = power * (1.0 + lam * rate)
    if force <= 0.0:
        return 0.0, 0.0, 0.0
    return force, exponent * power / delta * (1.0 + lam * rate), power * lam


@jit
def overlap_and_rate(prob, C, k, y, src):
    """(δ, δ̇) of a closed Hertz contact: its monitor row holds -w on z and on ż, +1 on its source."""
    n, ns = prob.ip[layout.IP_N], prob.ip[layout.IP_NS]
    row = C.mon[k]
    delta = 0.0
    rate = 0.0
    for j in range(n):
        delta += row[j] * y[layout.Z, j]
        rate += row[n + j] * y[layout.ZD, j]
    for s in range(ns):
        delta += row[3 * n + 3 * s] * src[3 * s]
        rate += row[3 * n + 3 * s + 1] * src[3 * s + 1]
    return delta, rate


@jit_inline
def linear_force(mon, k, n, ns, count, z, zd, zdd, src):
    """Contact force of closed clearance k from its monitor row mon[k] on (z, ż, z̈, sources, 1) (the
    first ``count`` z indices), summed term by term in the order z_0, ż_0, z̈_0, z_1, …, then the
    sources. (A quiet step takes the same force, up to round-off, from its force row in the step's
    product: see ``layout.CP_RAW``.)"""
    f = mon[k, 3 * n + 3 * ns]
    for j in range(count):
        f += mon[k, j] * z[j]
        f += mon[k, n + j] * zd[j]
        f += mon[k, 2 * n + j] * zdd[j]
    for j in range(3 * ns):
        f += mon[k, 3 * n + j] * src[j]
    return f


@jit
def rigid_force(prob, C, k, y, src, hertz):
    """Contact force of closed rigid clearance k: its linear row, plus the closed Hertz contacts' pull
    on it (``mon[k, 3n + 3ns + 1 + j]`` per unit Hertz force F_j)."""
    f = linear_force(C.mon, k, prob.ip[layout.IP_N], prob.ip[layout.IP_NS], C.mk[k, layout.MK_M], y[layout.Z],
                     y[layout.ZD], y[layout.ZDD], src)
    if hertz is not None:
        head = 3 * prob.ip[layout.IP_N] + 3 * prob.ip[layout.IP_NS] + 1
        for j in range(prob.cl.shape[0]):
            if C.mon[k, head + j] != 0.0:
                delta, rate = overlap_and_rate(prob, C, j, y, src)
                f += C.mon[k, head + j] * hertz_force(prob.clf, j, delta, rate)[0]
    return f


@jit
def compliant_force(prob, C, k, y, src, hertz):
    """Contact force of closed compliant clearance k: the Hertz law, or its linear row."""
    if hertz is not None:
        if prob.cl[k, layout.CL_SOFT] == layout.SOFT_HERTZ:
            delta, rate = overlap_and_rate(prob, C, k, y, src)
            return hertz_force(prob.clf, k, delta, rate)[0]
    return linear_force(C.mon, k, prob.ip[layout.IP_N], prob.ip[layout.IP_NS], C.mk[k, layout.MK_M], y[layout.Z],
                        y[layout.ZD], y[layout.ZDD], src)


@jit_inline
def signed_gap(kind, gap, gap_noise):
    """The monitor of an open clearance (its gap) or a closed compliant one (its overlap, -gap), plus
    the round-off allowance: negative past the event. Scalars only: an inline helper handed arrays
    takes and drops a reference count of each at every call, and this one runs per clearance and step."""
    return (gap if kind == layout.MK_GAP else -gap) + gap_noise


@jit
def monitors(prob, C, y, src, gap_noise, phi, hertz):
    """phi[k] = what changes sign at clearance k's next event, for every clearance k; 0 when not monitored.

    Open: gap + allowance. Closed rigid: the contact force. Closed compliant: the overlap δ = -gap +
    allowance (the contact ends when the parts part). Gaps and linear forces on arrays taken out of
    the records once; with no Hertz contact (``hertz`` None) nothing else is called."""
    n, ns = prob.ip[layout.IP_N], prob.ip[layout.IP_NS]
    mk, mon, z, zd, zdd, clf = C.mk, C.mon, y[layout.Z], y[layout.ZD], y[layout.ZDD], prob.clf
    for k in range(prob.cl.shape[0]):
        kind = mk[k, layout.MK_KIND]
        if kind == layout.MK_GAP or kind == layout.MK_OVERLAP:
            behind = mk[k, layout.MK_BEHIND]
            other = z[behind] if behind >= 0 else src[3 * (-1 - behind)]
            gap = clf[k, layout.CLF_SIGN] * (z[mk[k, layout.MK_AHEAD]] - other) + clf[k, layout.CLF_OPEN]
            phi[k] = signed_gap(kind, gap, gap_noise)
        elif kind == layout.MK_FORCE:
            if hertz is None:  # the linear row alone
                phi[k] = linear_force(mon, k, n, ns, mk[k, layout.MK_M], z, zd, zdd, src)
            else:
                phi[k] = rigid_force(prob, C, k, y, src, hertz)
        else:
            phi[k] = 0.0


@jit
def hertz_correction(prob, C, W, h, which):
    """Add the closed Hertz contacts' forces to the Newmark step into W.y[Y_END] whose linear part is done.

    With the linear accelerations u (in z̈1) and V_j = S⁻¹ w_j (w_j: contact
    j's direction on the free rows), z̈_F = u + Σ V_j F_j, and each overlap is
    affine in the forces: δ_k = δ_k⁰ - βh² Σ w_kᵀV_j F_j, δ̇_k = δ̇_k⁰ - γh
    Σ w_kᵀV_j F_j. Newton on F_k = H_k(δ_k(F), δ̇_k(F)) (a system of the
    closed Hertz contacts' size); then the state takes the forces.
    """
    beta, gamma = prob.fp[layout.FP_BETA], prob.fp[layout.FP_GAMMA]
    end = W.y[layout.Y_END]
    nf = C.ci[layout.CI_NF]
    ncl = prob.cl.shape[0]
    idx = np.empty(ncl, dtype=np.int64)
    nc = 0
    for k in range(ncl):
        if C.mk[k, layout.MK_KIND] == layout.MK_OVERLAP and prob.cl[k, layout.CL_SOFT] == layout.SOFT_HERTZ:
            idx[nc] = k
            nc += 1
    if nc == 0:
        return
    V = np.zeros((nf, nc))
    w = np.zeros(nf)
    col = np.zeros(nf)
    for j in range(nc):
        for f in range(nf):
            w[f] = -C.mon[idx[j], f]
        effective_solve(C, which, W.L, w, col)
        for f in range(nf):
            V[f, j] = col[f]
    A = np.zeros((nc, nc))  # δ_k per unit F_j, before the βh² and γh factors: -w_kᵀ V_j
    d0 = np.zeros(nc)
    r0 = np.zeros(nc)
    for i in range(nc):
        d0[i], r0[i] = overlap_and_rate(prob, C, idx[i], end, W.src[layout.SRC_END])
        for j in range(nc):
            acc = 0.0
            for f in range(nf):
                acc += C.mon[idx[i], f] * V[f, j]
            A[i, j] = acc
    F = np.zeros(nc)
    R = np.zeros(nc)
    J = np.zeros((nc, nc))
    dF = np.zeros(nc)
    scale = 0.0
    for _ in range(60):
        for i in range(nc):
            delta = d0[i]
            rate = r0[i]
            for j in range(nc):
                delta += beta * h * h * A[i, j] * F[j]
                rate += gamma * h * A[i, j] * F[j]
            value, d_delta, d_rate = hertz_force(prob.clf, idx[i], delta, rate)
            R[i] = value - F[i]
            for j in range(nc):
                J[i, j] = (d_delta * beta * h * h + d_rate * gamma * h) * A[i, j] - (1.0 if i == j else 0.0)
            scale = max(scale, abs(value))
        solve_dense(J, R, dF, nc)
        change = 0.0
        for i in range(nc):
            F[i] = max(F[i] - dF[i], 0.0)
            change = max(change, abs(dF[i]))
        if change <= 1e-12 * scale + 1e-300:
            break
    for f in range(nf):
        acc = 0.0
        for j in range(nc):
            acc += V[f, j] * F[j]
        end[layout.ZDD, f] += acc
        end[layout.Z, f] += beta * h * h * acc
        end[layout.ZD, f] += gamma * h * acc
