"""The impact laws and the event rules: impacts, releases, settling after a transition.

Every back end applies these (the piecewise ones call :func:`apply_impacts`,
:func:`release_pulling`, :func:`shut_gap` and :func:`gap_velocity` from
Python). An event is a row of the output record's event buffers
(:func:`add_event`).
"""

from __future__ import annotations

import math

import numpy as np

from vtool.jit import jit, jit_inline
from vtool.solvers.newmark import layout
from vtool.solvers.newmark.kernel.algebra import solve_dense
from vtool.solvers.newmark.kernel.forces import linear_force, rigid_force
from vtool.solvers.newmark.kernel.step import (
    configuration,
    consistent_acceleration,
    find_slot,
    gather,
    scatter,
)


@jit_inline
def add_event(O, S, t, k, kind, u, c_from, c_to):
    """Event row: time, relative velocity; clearance, kind, configuration before and after."""
    row = S.ist[layout.I_NEV]
    if row < O.ev_f.shape[0]:
        O.ev_f[row, 0] = t
        O.ev_f[row, 1] = u
        O.ev_i[row, 0] = k
        O.ev_i[row, 1] = kind
        O.ev_i[row, 2] = c_from
        O.ev_i[row, 3] = c_to
    S.ist[layout.I_NEV] = row + 1


@jit_inline
def solve_impulse_lcp(W, u, b, eq, scale, P, uplus):
    """Impulses P >= 0 with u + W P - b >= 0 and complementarity (equalities: = b).

    Enumerates active sets, most contacts first; W is positive definite, so
    exactly one set satisfies the conditions (to the tolerance ``scale``).
    Writes P and u⁺ = u + W P.
    """
    nc = u.shape[0]
    active = np.zeros(nc, dtype=np.int64)
    Wa = np.zeros((nc, nc))
    ra = np.zeros(nc)
    sol = np.zeros(nc)
    for pattern in range(2**nc - 1, -1, -1):
        na = 0
        for r in range(nc):
            P[r] = 0.0
            if eq[r] or (pattern >> r) & 1:
                active[na] = r
                na += 1
        for p in range(na):
            ra[p] = b[active[p]] - u[active[p]]
            for q in range(na):
                Wa[p, q] = W[active[p], active[q]]
        solve_dense(Wa, ra, sol, na)
        for p in range(na):
            P[active[p]] = sol[p]
        ok = True
        for r in range(nc):
            s = u[r]
            for q in range(nc):
                s += W[r, q] * P[q]
            uplus[r] = s
            if not eq[r] and (P[r] * W[r, r] < -10.0 * scale or s - b[r] < -10.0 * scale):
                ok = False
        if ok:
            return
    for r in range(nc):
        P[r] = 0.0
        uplus[r] = u[r]


@jit_inline
def impact_momentum(prob, c, closing, src, S, stick, O, t):
    """Newton impact with restitution, impulses of all contacts together on the consistent mass matrix.

    Contacts taking part: every clearance closed in c (persistent) and the
    closing ones with the ``momentum`` law. With G their velocity-constraint
    rows (internal: e_ahead - e_behind; external: e_ahead), relative
    velocities u = G v - w (w: source velocity) and the Delassus matrix
    W = G M⁻¹ Gᵀ, the impulses P solve the linear complementarity problem

        u⁺ = u⁻ + W P,   P >= 0,   u⁺ - b >= 0,   P · (u⁺ - b) = 0

    with b = -e u⁻ for a closing contact (Newton's law) and b = 0 for a
    persistent one (it may separate, but not penetrate); pinned clearances are
    equalities. Then v⁺ = v⁻ + M⁻¹ Gᵀ P conserves generalised momentum. A
    contact is closed afterwards when it leaves with no separating relative
    velocity; a persistent one that the impulse pulls apart is released.
    Separations slower than the resting velocity are resting contacts (held
    as equalities); in ``stick`` mode (chattering) every contact involved is.
    """
    ip, fp, cl, clf, mass = prob.ip, prob.fp, prob.cl, prob.clf, prob.mass
    v = S.v
    n = ip[layout.IP_N]
    ncl = ip[layout.IP_NCL]
    idx = np.empty(ncl, dtype=np.int64)
    nc = 0
    for k in range(ncl):
        if ((c & cl[k, layout.CL_BIT]) and not cl[k, layout.CL_SOFT]) or closing[k]:
            idx[nc] = k
            nc += 1
    u = np.zeros(nc)
    b = np.zeros(nc)
    eq = np.zeros(nc, dtype=np.int64)
    MG = np.zeros((n, nc))  # M⁻¹ Gᵀ
    for r in range(nc):
        k = idx[r]
        ahead, behind = cl[k, layout.CL_AHEAD], cl[k, layout.CL_BEHIND]
        # G's row is e_ahead - e_behind, or e_ahead with w the source's velocity: u = G v - w and M⁻¹ Gᵀ by
        # their entries, each sum begun at 0.0 as a dot product with G's row (the same bits, zeros' signs too)
        u[r] = 0.0 + v[ahead] - (v[behind] if behind >= 0 else src[3 * cl[k, layout.CL_SRC] + 1])
        for i in range(n):
            MG[i, r] = 0.0 + mass[1, i, ahead] - (mass[1, i, behind] if behind >= 0 else 0.0)
        if closing[k]:
            e = 0.0 if (stick or abs(u[r]) < fp[layout.FP_VREST]) else clf[k, layout.CLF_E]
            b[r] = -e * u[r]
        eq[r] = cl[k, layout.CL_PIN] or stick
    W = np.zeros((nc, nc))  # G M⁻¹ Gᵀ
    for r in range(nc):
        ahead, behind = cl[idx[r], layout.CL_AHEAD], cl[idx[r], layout.CL_BEHIND]
        for q in range(nc):
            W[r, q] = 0.0 + MG[ahead, q] - (MG[behind, q] if behind >= 0 else 0.0)
    umax = 0.0
    for r in range(nc):
        umax = max(umax, abs(u[r]))
    scale = 1e-12 + 1e-9 * umax
    P = np.zeros(nc)
    uplus = np.zeros(nc)
    for _ in range(nc + 1):
        solve_impulse_lcp(W, u, b, eq, scale, P, uplus)
        resting = False
        for r in range(nc):
            if not eq[r] and 10.0 * scale < uplus[r] < fp[layout.FP_VREST]:
                eq[r] = 1
                b[r] = 0.0
                resting = True
        if not resting:
            break
    for i in range(n):
        for r in range(nc):
            v[i] += MG[i, r] * P[r]
    mask = c
    for r in range(nc):
        k = idx[r]
        stays = eq[r] or uplus[r] <= 10.0 * scale
        if stays:
            mask |= cl[k, layout.CL_BIT]
        else:
            mask &= ~cl[k, layout.CL_BIT]
    for r in range(nc):
        k = idx[r]
        if closing[k]:
            add_event(O, S, t, k, layout.EV_CLOSED, u[r], c, mask)
        elif not (mask & cl[k, layout.CL_BIT]):
            add_event(O, S, t, k, layout.EV_RELEASED, uplus[r], c, mask)
    return mask


@jit_inline
def prescribed_velocity(cl, c, ncl, coordinate, src):
    """Velocity of the source a coordinate is tied to in configuration c, or nan if it is free."""
    for k in range(ncl):
        if ((c & cl[k, layout.CL_BIT]) and not cl[k, layout.CL_SOFT] and cl[k, layout.CL_BEHIND] < 0
                and cl[k, layout.CL_AHEAD] == coordinate):
            return src[3 * cl[k, layout.CL_SRC] + 1]
    return math.nan


@jit_inline
def impact_local(prob, c, k, src, S, stick, O, t):
    """The thesis' local law at one closing clearance k (see the module doc); returns the new mask.

    External: the impacting coordinate a takes the source velocity w with
    restitution, v_a⁺ = w - e (v_a⁻ - w); nothing else changes. Internal
    (a ahead, b behind, relative velocity u⁻ = v_a - v_b): with diagonal
    masses m_a, m_b the common velocity U = (m_a v_a + m_b v_b)/(m_a + m_b)
    (law ``thesis``: U = SCALE v_a, Gnilka eq. 3.54), and
    v_a⁺ = U + m_b/(m_a + m_b) u⁺, v_b⁺ = U - m_a/(m_a + m_b) u⁺ with
    u⁺ = -e u⁻. A coordinate of the pair that is tied to a source counts as
    infinitely heavy. A contact that leaves with a separating velocity
    (e > 0, above the resting velocity) stays open.
    """
    ip, fp, cl, clf, mass = prob.ip, prob.fp, prob.cl, prob.clf, prob.mass
    v = S.v
    ncl = ip[layout.IP_NCL]
    a = cl[k, layout.CL_AHEAD]
    behind = cl[k, layout.CL_BEHIND]
    if behind < 0:
        w = src[3 * cl[k, layout.CL_SRC] + 1]
        u = v[a] - w
        e = 0.0 if (stick or abs(u) < fp[layout.FP_VREST]) else clf[k, layout.CLF_E]
        v[a] = w - e * u
    else:
        u = v[a] - v[behind]
        e = 0.0 if (stick or abs(u) < fp[layout.FP_VREST]) else clf[k, layout.CLF_E]
        wa = prescribed_velocity(cl, c, ncl, a, src)
        wb = prescribed_velocity(cl, c, ncl, behind, src)
        if not math.isnan(wa):  # a follows a source: b alone changes
            v[behind] = wa + e * u
        elif not math.isnan(wb):
            v[a] = wb - e * u
        else:
            ma = mass[0, a, a]
            mb = mass[0, behind, behind]
            if cl[k, layout.CL_LAW] == layout.LAW_THESIS:
                common = clf[k, layout.CLF_SCALE] * v[a]
            else:
                common = (ma * v[a] + mb * v[behind]) / (ma + mb)
            uplus = -e * u
            v[a] = common + mb / (ma + mb) * uplus
            v[behind] = common - ma / (ma + mb) * uplus
    mask = c
    if e * abs(u) <= 0.0:
        mask |= cl[k, layout.CL_BIT]
    add_event(O, S, t, k, layout.EV_CLOSED, u, c, mask)
    return mask


@jit_inline
def shut_gap(cl, clf, k, x, src):
    """Clearance k's gap (or overlap) set to exactly zero: it is within the time tolerance of zero
    (sense (x_ahead - x_behind) + opening = 0)."""
    other = x[cl[k, layout.CL_BEHIND]] if cl[k, layout.CL_BEHIND] >= 0 else src[3 * cl[k, layout.CL_SRC]]
    x[cl[k, layout.CL_AHEAD]] = other - clf[k, layout.CLF_SIGN] * clf[k, layout.CLF_OPEN]


@jit_inline
def gap_velocity(cl, clf, k, v, src):
    """Velocity of clearance k's gap: sense (v_ahead - v_behind (or the source's))."""
    behind = cl[k, layout.CL_BEHIND]
    other = v[behind] if behind >= 0 else src[3 * cl[k, layout.CL_SRC] + 1]
    return clf[k, layout.CLF_SIGN] * (v[cl[k, layout.CL_AHEAD]] - other)

@jit
def apply_impacts(prob, c, closing, src, S, stick, O, t, momentum):
    """Apply the impact law of every closing clearance at t; returns the new configuration mask.

    Local-law closings are applied one after the other (each changes only its
    own coordinates); momentum-law closings are solved together with every
    closed contact (:func:`impact_momentum`). Gaps are snapped shut (they are
    within the time tolerance). A compliant clearance closes with no jump: its
    spring and dashpot take over (the event records its approach velocity).
    """
    ip, fp, cl, clf = prob.ip, prob.fp, prob.cl, prob.clf
    x, v = S.x, S.v
    ncl = ip[layout.IP_NCL]
    mask = c
    any_momentum = False
    for k in range(ncl):
        if not closing[k]:
            continue
        shut_gap(cl, clf, k, x, src)
        if cl[k, layout.CL_SOFT]:
            mask |= cl[k, layout.CL_BIT]
            u = gap_velocity(cl, clf, k, v, src)
            clf[k, layout.CLF_HV] = max(-u, fp[layout.FP_VREST], 1e-300)  # the Hertz contact's approach velocity
            add_event(O, S, t, k, layout.EV_CLOSED, u, c, mask)
        elif cl[k, layout.CL_LAW] == layout.LAW_MOMENTUM:
            any_momentum = True
        else:
            mask = impact_local(prob, mask, k, src, S, stick, O, t)
    if momentum is not None:  # None: no clearance has the momentum law (see laws), and no array is made
        if any_momentum:
            joint = np.zeros(ncl, dtype=np.int64)  # the momentum-law closings, solved together
            for k in range(ncl):
                if closing[k] and not cl[k, layout.CL_SOFT] and cl[k, layout.CL_LAW] == layout.LAW_MOMENTUM:
                    joint[k] = 1
            mask = impact_momentum(prob, mask, joint, src, S, stick, O, t)
    return mask


@jit
def release_pulling(prob, T, c, t, S, src, O, y, rhs, hertz):
    """Consistent accelerations of configuration c; release at once every contact that would pull.

    Returns the settled configuration, or -1 - c2 when configuration c2 must
    be built first (call again after building it). The most pulling contact
    is released first and the accelerations recomputed, until every closed
    contact pushes (at most one release per clearance).
    """
    ip, fp, cl = prob.ip, prob.fp, prob.cl
    n = ip[layout.IP_N]
    ncl = ip[layout.IP_NCL]
    for _ in range(ncl + 1):
        slot = find_slot(T.index, c)
        if slot < 0:
            return -1 - c
        C = configuration(T, c, slot)
        gather(C, n, S, y)
        consistent_acceleration(prob, C, src, y, rhs, hertz)
        scatter(C, n, y, S)
        worst = -1
        worst_f = -fp[layout.FP_FTOL]
        for k in range(ncl):
            if C.mk[k, layout.MK_KIND] == layout.MK_FORCE and cl[k, layout.CL_MON]:
                if hertz is None:  # the linear row alone (rigid_force's, with no Hertz contact)
                    f = linear_force(C.mon, k, n, ip[layout.IP_NS], C.mk[k, layout.MK_M], y[layout.Z], y[layout.ZD],
                                     y[layout.ZDD], src)
                else:
                    f = rigid_force(prob, C, k, y, src, hertz)
                if f < worst_f:
                    worst = k
                    worst_f = f
        if worst < 0:
            return c
        new_c = c & ~cl[worst, layout.CL_BIT]
        add_event(O, S, t, worst, layout.EV_OPENED, 0.0, c, new_c)
        c = new_c
    return c


@jit_inline
def take_events(prob, c, t, h, W, S, O, momentum):
    """The events at t of configuration c: each monitor k that crossed within the time tolerance of
    the located step h (``tau[k] <= h + tol``) opens its contact, or closes it by an impact. Returns
    the configuration after them, or -1 when the contacts chatter (``IP_ZSTOP`` rapid events)."""
    ip, fp, cl = prob.ip, prob.fp, prob.cl
    x, v, ist, fst = S.x, S.v, S.ist, S.fst
    tau, closing, src0 = W.cross[layout.TAU], W.closing, W.src[layout.SRC_NOW]
    ncl = ip[layout.IP_NCL]
    tol = fp[layout.FP_TTOL]
    new_c = c
    any_closing = False
    for k in range(ncl):
        closing[k] = 0
        if cl[k, layout.CL_MON] and tau[k] <= h + tol:
            if c & cl[k, layout.CL_BIT]:
                new_c &= ~cl[k, layout.CL_BIT]
            else:
                closing[k] = 1
                any_closing = True
    rapid = t - fst[layout.F_LAST_EVENT] <= fp[layout.FP_ZWIN]
    ist[layout.I_RAPID] = ist[layout.I_RAPID] + 1 if rapid else 0
    fst[layout.F_LAST_EVENT] = t
    if ist[layout.I_RAPID] >= ip[layout.IP_ZSTOP]:
        return -1
    stick = ist[layout.I_RAPID] >= ip[layout.IP_ZSTICK]
    for k in range(ncl):
        if (c & cl[k, layout.CL_BIT]) and not (new_c & cl[k, layout.CL_BIT]):
            u = 0.0
            if cl[k, layout.CL_SOFT]:  # the parts leave with their relative velocity; the overlap is shut
                shut_gap(cl, prob.clf, k, x, src0)
                u = gap_velocity(cl, prob.clf, k, v, src0)
            add_event(O, S, t, k, layout.EV_OPENED, u, c, new_c)
    if any_closing:
        new_c = apply_impacts(prob, new_c, W.closing, W.src[layout.SRC_NOW], S, stick, O, t, momentum)
    return new_c


