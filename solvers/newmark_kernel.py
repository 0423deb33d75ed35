"""Compiled Newmark integration of the valve train with clearances (numba).

Everything the run loop touches lives in this one module (the numba cache
misses edits in other files). The same source, run with
``NUMBA_DISABLE_JIT=1``, is the plain-NumPy reference the tests compare the
compiled kernel with.

Conventions
-----------
Full coordinates: the n elastic system coordinates q_1..q_n (0-based here).
Sources: prescribed motions (0: harmonic cam ``p0 sin(p1 t) + p2``; 1: fixed
seat at ``p0``). A configuration ``c`` is a bit mask over the clearances
(contact = 1). In configuration c the layer coordinates x_L (size m) are the
full ones with every closed internal pair tied; ``group[c, i]`` is the layer
column of full coordinate i and ``kept[c, j]`` a full coordinate of layer
column j. Layer columns tied to a source (closed external clearance) are
prescribed (P); the others are free (F).

Newmark step of length h in configuration c (general beta, gamma):

    x̃ = x + h v + h²(1/2 - beta) a,   ṽ = v + h(1 - gamma) a
    S a_F = -C_FF ṽ_F - K_FF x̃_F - (M_FP a_P + C_FP v_P + K_FP x_P)     (ΔP)
    S = M_FF + gamma h C_FF + beta h² K_FF          (thesis BMIV = S⁻¹)
    x_F = x̃_F + beta h² a_F,   v_F = ṽ_F + gamma h a_F

with the prescribed values (x_P, v_P, a_P) taken from the sources at t + h.

Contact forces: one row of coefficients per (configuration, clearance) on
the full state and the sources (see :mod:`vtool.solvers.configurations`),
positive in compression.

Status codes returned by :func:`run_chunk` are the ``STATUS_*`` values in
:mod:`vtool.solvers.newmark`, passed in as plain integers.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

jit = njit(cache=True, nogil=True)
leaf = njit(cache=True, nogil=True, inline="always")

Problem = namedtuple(
    "Problem",
    [
        "n",  # number of full (elastic) coordinates
        "beta",
        "gamma",
        "dt",  # standard time step, s
        "t_end",  # end of the run, s
        "out_dt",  # output interval, s (ignored when every_step)
        "every_step",  # 1: record every accepted (sub)step
        "cl_ahead",  # int[ncl]: full index of the coordinate ahead when open
        "cl_behind",  # int[ncl]: full index behind (internal) or -1
        "cl_src",  # int[ncl]: source index behind (external) or -1
        "cl_monitored",  # int[ncl]: 1 for enabled clearances (pinned/removed: 0)
        "cl_pinned",  # int[ncl]: 1 for pinned clearances
        "cl_e",  # float[ncl]: restitution coefficient
        "cl_bit",  # int[ncl]: bit of the clearance in the configuration mask
        "src_kind",  # int[ns]
        "src_par",  # float[ns, 3]
        "Minv",  # float[n, n]: inverse of the full mass matrix (impacts)
        "time_tol",  # event location tolerance in time, s
        "zeno_window",  # events closer than this count as rapid, s
        "zeno_stick",  # rapid events before contacts are made to stick
        "zeno_stop",  # rapid events before the run stops
        "x_limit",  # |q| beyond this is divergence
        "rest_velocity",  # slower separations and impacts are resting contacts
        "gap_noise",  # gaps within this of zero are round-off (length)
        "refine",  # after an event, steps are dt / refine ...
        "refine_window",  # ... for this long (s)
    ],
)

Configs = namedtuple(
    "Configs",
    ["built", "m", "kept", "group", "nf", "free", "npres", "pres", "pres_src",
     "ML", "CL", "KL", "Sinv", "SinvFine", "MinvFF", "Frow"],
)

Output = namedtuple(
    "Output",
    ["t", "x", "v", "a", "F", "cfg", "ev_t", "ev_k", "ev_kind", "ev_u", "ev_from", "ev_to", "F_peak"],
)

Work = namedtuple(
    "Work",
    ["xl", "vl", "al", "rhs", "S", "Sinv", "x0", "v0", "a0", "x1", "v1", "a1",
     "phi", "tau", "xo", "vo", "ao", "src"],
)

# istate / fstate slots (documented in vtool.solvers.newmark)
I_CFG, I_NOUT, I_NEV, I_STEPS, I_RAPID, I_GRID, I_NEXT_OUT, I_NEED_ACCEL, I_WANT_CFG = range(9)
F_T, F_LAST_EVENT, F_CHUNK_END, F_FINE_UNTIL = range(4)


@leaf
def source_state(src_kind, src_par, s, t):
    """Displacement, velocity and acceleration of prescribed source s at time t."""
    if src_kind[s] == 0:
        amp = src_par[s, 0]
        w = src_par[s, 1]
        sw = np.sin(w * t)
        return amp * sw + src_par[s, 2], amp * w * np.cos(w * t), -amp * w * w * sw
    return src_par[s, 0], 0.0, 0.0


@leaf
def gather(cfg, c, x, v, a, xl, vl, al):
    """Layer values of configuration c from full arrays (tied coordinates are equal)."""
    for j in range(cfg.m[c]):
        i = cfg.kept[c, j]
        xl[j] = x[i]
        vl[j] = v[i]
        al[j] = a[i]


@leaf
def scatter(prob, cfg, c, xl, vl, al, x, v, a):
    for i in range(prob.n):
        j = cfg.group[c, i]
        x[i] = xl[j]
        v[i] = vl[j]
        a[i] = al[j]


@leaf
def set_prescribed(prob, cfg, c, t, xl, vl, al):
    for p in range(cfg.npres[c]):
        j = cfg.pres[c, p]
        xl[j], vl[j], al[j] = source_state(prob.src_kind, prob.src_par, cfg.pres_src[c, p], t)


@leaf
def free_rhs(cfg, c, xl, vl, al, rhs):
    """rhs_F = -C_FF v_F - K_FF x_F - (M_FP a_P + C_FP v_P + K_FP x_P): the thesis' ΔP on the right."""
    nf, npres = cfg.nf[c], cfg.npres[c]
    for f in range(nf):
        jf = cfg.free[c, f]
        s = 0.0
        for g in range(nf):
            jg = cfg.free[c, g]
            s -= cfg.CL[c, jf, jg] * vl[jg] + cfg.KL[c, jf, jg] * xl[jg]
        for p in range(npres):
            jp = cfg.pres[c, p]
            s -= cfg.ML[c, jf, jp] * al[jp] + cfg.CL[c, jf, jp] * vl[jp] + cfg.KL[c, jf, jp] * xl[jp]
        rhs[f] = s


@jit
def effective_inverse(prob, cfg, c, h, S, Sinv):
    """Sinv = (M_FF + gamma h C_FF + beta h² K_FF)⁻¹ for a non-standard step h."""
    nf = cfg.nf[c]
    for f in range(nf):
        jf = cfg.free[c, f]
        for g in range(nf):
            jg = cfg.free[c, g]
            S[f, g] = (cfg.ML[c, jf, jg] + prob.gamma * h * cfg.CL[c, jf, jg]
                       + prob.beta * h * h * cfg.KL[c, jf, jg])
    Sinv[:nf, :nf] = np.linalg.inv(S[:nf, :nf])


@leaf
def newmark_step(prob, cfg, c, t, h, Sinv, x, v, a, w, x1, v1, a1):
    """One Newmark step of length h in configuration c from full (x, v, a) at t.

    Writes the full state at t + h into (x1, v1, a1) and leaves the layer
    state at t + h in (w.xl, w.vl, w.al) for the contact forces.
    """
    beta, gamma = prob.beta, prob.gamma
    m, nf = cfg.m[c], cfg.nf[c]
    xl, vl, al = w.xl, w.vl, w.al
    gather(cfg, c, x, v, a, xl, vl, al)
    for j in range(m):  # predictors x̃, ṽ (overwritten for prescribed columns)
        xl[j] += h * vl[j] + h * h * (0.5 - beta) * al[j]
        vl[j] += h * (1.0 - gamma) * al[j]
    set_prescribed(prob, cfg, c, t + h, xl, vl, al)
    free_rhs(cfg, c, xl, vl, al, w.rhs)
    for f in range(nf):
        s = 0.0
        for g in range(nf):
            s += Sinv[f, g] * w.rhs[g]
        jf = cfg.free[c, f]
        al[jf] = s
        xl[jf] += beta * h * h * s
        vl[jf] += gamma * h * s
    scatter(prob, cfg, c, xl, vl, al, x1, v1, a1)


@leaf
def fill_sources(prob, t, src):
    """src[3s : 3s + 3] = (x, v, a) of every prescribed source s at time t."""
    for s in range(prob.src_kind.shape[0]):
        src[3 * s], src[3 * s + 1], src[3 * s + 2] = source_state(prob.src_kind, prob.src_par, s, t)


@leaf
def gap(prob, k, x, src):
    """q[ahead] - q[behind] of clearance k (positive while open); src from :func:`fill_sources`."""
    if prob.cl_behind[k] >= 0:
        return x[prob.cl_ahead[k]] - x[prob.cl_behind[k]]
    return x[prob.cl_ahead[k]] - src[3 * prob.cl_src[k]]


@leaf
def consistent_acceleration(prob, cfg, c, t, x, v, a, xl, vl, al, rhs):
    """Accelerations (into a) from the equations of motion of configuration c at t.

    Uses the layer scratch arrays (xl, vl, al, rhs) given, so a caller can
    keep another layer state alive.
    """
    gather(cfg, c, x, v, a, xl, vl, al)
    set_prescribed(prob, cfg, c, t, xl, vl, al)
    nf = cfg.nf[c]
    free_rhs(cfg, c, xl, vl, al, rhs)
    for f in range(nf):
        s = 0.0
        for g in range(nf):
            s += cfg.MinvFF[c, f, g] * rhs[g]
        al[cfg.free[c, f]] = s
    for i in range(prob.n):
        a[i] = al[cfg.group[c, i]]


@leaf
def contact_force(prob, cfg, c, k, x, v, a, src):
    """Contact force of clearance k in configuration c, positive in compression.

    A row of coefficients per (configuration, clearance) on the full state
    and the sources (see :mod:`vtool.solvers.configurations`); zero when open.
    ``src`` holds the sources at the same instant (:func:`fill_sources`).
    """
    n = prob.n
    f = 0.0
    for i in range(n):
        f += cfg.Frow[c, k, i] * x[i] + cfg.Frow[c, k, n + i] * v[i] + cfg.Frow[c, k, 2 * n + i] * a[i]
    for j in range(src.shape[0]):
        f += cfg.Frow[c, k, 3 * n + j] * src[j]
    return f


@leaf
def monitor(prob, cfg, c, k, x, v, a, src):
    """The value whose sign change flips clearance k: its contact force if closed, its gap if open.

    A gap counts as closed when it is below -gap_noise (1e-13 of the
    mechanism's size): a gap that starts at zero (a contact just released,
    or separating tangentially) has a round-off sign until it has moved.
    """
    if c & prob.cl_bit[k]:
        return contact_force(prob, cfg, c, k, x, v, a, src)
    return gap(prob, k, x, src) + prob.gap_noise


@leaf
def step_to(prob, cfg, c, t, h, x, v, a, w, x1, v1, a1):
    """A Newmark step of any length h (standard steps reuse the stored inverse)."""
    if h == prob.dt:
        newmark_step(prob, cfg, c, t, h, cfg.Sinv[c], x, v, a, w, x1, v1, a1)
    elif h == prob.dt / prob.refine:
        newmark_step(prob, cfg, c, t, h, cfg.SinvFine[c], x, v, a, w, x1, v1, a1)
    else:
        effective_inverse(prob, cfg, c, h, w.S, w.Sinv)
        newmark_step(prob, cfg, c, t, h, w.Sinv, x, v, a, w, x1, v1, a1)


@jit
def locate_event(prob, cfg, c, k, t, lo, h, phi_lo, phi_hi, x, v, a, w):
    """Earliest tau in (lo, h] where monitor k crosses zero, re-stepping from t.

    Illinois (modified regula falsi) on phi(tau) = monitor after a Newmark
    step of length tau, bracketed by phi(lo) >= 0 > phi(h), with a bisection
    whenever two iterations have not halved the bracket; returns the left end
    of the final bracket (the monitor still non-negative), within
    prob.time_tol of the crossing.
    """
    hi = h
    flo, fhi = phi_lo, phi_hi
    side = 0
    width_before = 2.0 * h
    for iteration in range(200):
        width = hi - lo
        if width <= prob.time_tol:
            break
        if iteration % 2 == 0:
            if width > 0.5 * width_before:
                tau = 0.5 * (lo + hi)  # slow progress: bisect
            else:
                tau = (lo * fhi - hi * flo) / (fhi - flo)
            width_before = width
        else:
            tau = (lo * fhi - hi * flo) / (fhi - flo)
        tau = min(max(tau, lo + 0.25 * prob.time_tol), hi - 0.25 * prob.time_tol)
        step_to(prob, cfg, c, t, tau, x, v, a, w, w.x1, w.v1, w.a1)
        fill_sources(prob, t + tau, w.src)
        f = monitor(prob, cfg, c, k, w.x1, w.v1, w.a1, w.src)
        if f < 0.0:
            hi, fhi = tau, f
            if side == -1:
                flo *= 0.5
            side = -1
        else:
            lo, flo = tau, f
            if side == 1:
                fhi *= 0.5
            side = 1
    return lo


@jit
def record(prob, cfg, c, t, x, v, a, w, out, row):
    """Write one output row at t: coordinates, sources and contact forces.

    The prescribed coordinates of configuration c are first set exactly from
    their sources (an interpolated state only approximates them).
    """
    n = prob.n
    gather(cfg, c, x, v, a, w.xl, w.vl, w.al)
    set_prescribed(prob, cfg, c, t, w.xl, w.vl, w.al)
    scatter(prob, cfg, c, w.xl, w.vl, w.al, x, v, a)
    out.t[row] = t
    out.cfg[row] = c
    for i in range(n):
        out.x[row, i] = x[i]
        out.v[row, i] = v[i]
        out.a[row, i] = a[i]
    fill_sources(prob, t, w.src)
    for s in range(prob.src_kind.shape[0]):
        out.x[row, n + s] = w.src[3 * s]
        out.v[row, n + s] = w.src[3 * s + 1]
        out.a[row, n + s] = w.src[3 * s + 2]
    for k in range(prob.cl_ahead.shape[0]):
        out.F[row, k] = contact_force(prob, cfg, c, k, x, v, a, w.src) if c & prob.cl_bit[k] else 0.0


@jit
def record_outputs(prob, cfg, c, t0, h, istate, out, w):
    """Record every output instant in (t0, t0 + h] by the linear-acceleration interpolant.

    Within a step the acceleration is taken linear (exact for beta = 1/6),
    so v and x are its quadratic and cubic integrals (thesis eqs. B.3–B.5).
    Returns False when the output buffer is full.
    """
    n = prob.n
    t1 = t0 + h
    if prob.every_step:
        row = istate[I_NOUT]
        if row >= out.t.shape[0]:
            return False
        record(prob, cfg, c, t1, w.x1, w.v1, w.a1, w, out, row)
        istate[I_NOUT] = row + 1
        return True
    while True:
        j = istate[I_NEXT_OUT]
        t_out = j * prob.out_dt
        if t_out > t1 + 1e-9 * prob.dt or t_out > prob.t_end + 1e-9 * prob.dt:
            return True
        row = istate[I_NOUT]
        if row >= out.t.shape[0]:
            return False
        tau = t_out - t0
        r = tau / h if h > 0 else 0.0
        for i in range(n):
            da = w.a1[i] - w.a0[i]
            w.ao[i] = w.a0[i] + da * r
            w.vo[i] = w.v0[i] + w.a0[i] * tau + da * tau * r / 2.0
            w.xo[i] = w.x0[i] + w.v0[i] * tau + w.a0[i] * tau * tau / 2.0 + da * tau * tau * r / 6.0
        record(prob, cfg, c, t_out, w.xo, w.vo, w.ao, w, out, row)
        istate[I_NOUT] = row + 1
        istate[I_NEXT_OUT] = j + 1


@jit
def add_event(out, istate, t, k, kind, u, c_from, c_to):
    row = istate[I_NEV]
    if row < out.ev_t.shape[0]:
        out.ev_t[row] = t
        out.ev_k[row] = k
        out.ev_kind[row] = kind
        out.ev_u[row] = u
        out.ev_from[row] = c_from
        out.ev_to[row] = c_to
    istate[I_NEV] = row + 1


@jit
def impact(prob, c, closing, t, x, v, stick, out, istate):
    """Newton impact with restitution at the closing clearances; returns the new mask.

    Contacts taking part: every clearance closed in c (persistent) and the
    closing ones. With G their velocity-constraint rows (internal:
    e_ahead - e_behind; external: e_ahead), relative velocities u = G v - w
    (w: source velocity) and the Delassus matrix W = G M⁻¹ Gᵀ, the impulses P
    solve the linear complementarity problem

        u⁺ = u⁻ + W P,   P >= 0,   u⁺ - b >= 0,   P · (u⁺ - b) = 0

    with b = -e u⁻ for a closing contact (Newton's law) and b = 0 for a
    persistent one (it may separate, but not penetrate); pinned clearances are
    equalities. Then v⁺ = v⁻ + M⁻¹ Gᵀ P conserves generalised momentum. The
    LCP (W positive definite) has one solution, found by enumerating the
    active sets. A contact is closed afterwards when it leaves with no
    separating relative velocity (plastic or grazing); a closing contact that bounces
    (e > 0) and a persistent one that the impulse pulls apart are open, and
    the latter is recorded as released.

    Resting contacts: with consistent mass matrices an impulse at one end of a
    bar moves the other end backwards (M⁻¹ has negative off-diagonal terms),
    so a cam impact on a pushrod squeezed against the rocker "releases" the
    rocker at a tiny speed, the rocker re-impacts within picoseconds, releases
    the cam, and so on without end. Any separation (or bounce) slower than
    ``prob.rest_velocity`` is therefore a resting contact: it becomes an
    equality with zero relative velocity (plastic), and whether it really
    separates is then decided smoothly by its contact force at the next
    step. The kinetic energy this can change is at most of order
    m v_rest², and none is created (an equality row with u⁻ = u⁺ = 0 does no
    work). In ``stick`` mode (chattering) restitution is taken as zero and
    every contact involved is held shut (equality), so the chattering ends in
    sticking contact whose forces then decide any separation.
    """
    n = prob.n
    ncl = prob.cl_ahead.shape[0]
    idx = np.empty(ncl, dtype=np.int64)
    nc = 0
    for k in range(ncl):
        if (c & prob.cl_bit[k]) or closing[k]:
            idx[nc] = k
            nc += 1
    G = np.zeros((nc, n))
    u = np.zeros(nc)
    b = np.zeros(nc)
    eq = np.zeros(nc, dtype=np.int64)
    for r in range(nc):
        k = idx[r]
        G[r, prob.cl_ahead[k]] = 1.0
        wsrc = 0.0
        if prob.cl_behind[k] >= 0:
            G[r, prob.cl_behind[k]] -= 1.0
        else:
            wsrc = source_state(prob.src_kind, prob.src_par, prob.cl_src[k], t)[1]
        for i in range(n):
            u[r] += G[r, i] * v[i]
        u[r] -= wsrc
        if closing[k]:
            e = 0.0 if (stick or abs(u[r]) < prob.rest_velocity) else prob.cl_e[k]
            b[r] = -e * u[r]
        eq[r] = prob.cl_pinned[k] or stick  # chattering: every contact involved sticks
    MG = prob.Minv @ G.T
    W = G @ MG
    scale = 1e-12 + 1e-9 * np.max(np.abs(u)) if nc > 0 else 1e-12
    P = np.zeros(nc)
    uplus = u.copy()
    for _ in range(nc + 1):
        P, uplus = solve_impulse_lcp(W, u, b, eq, scale)
        resting = False
        for r in range(nc):  # slow separations are resting contacts: they stay closed
            if not eq[r] and 10.0 * scale < uplus[r] < prob.rest_velocity:
                eq[r] = 1
                b[r] = 0.0
                resting = True
        if not resting:
            break
    dv = MG @ P
    for i in range(n):
        v[i] += dv[i]
    mask = c
    for r in range(nc):
        k = idx[r]
        if closing[k]:  # snap the gap shut at the event (it is within the time tolerance)
            if prob.cl_behind[k] >= 0:
                x[prob.cl_ahead[k]] = x[prob.cl_behind[k]]
            else:
                x[prob.cl_ahead[k]] = source_state(prob.src_kind, prob.src_par, prob.cl_src[k], t)[0]
        stays = eq[r] or uplus[r] <= 10.0 * scale  # no separating velocity: in contact
        if stays:
            mask |= prob.cl_bit[k]
        else:
            mask &= ~prob.cl_bit[k]
    for r in range(nc):
        k = idx[r]
        if closing[k]:
            add_event(out, istate, t, k, 1, u[r], c, mask)
        elif not (mask & prob.cl_bit[k]):
            add_event(out, istate, t, k, 2, uplus[r], c, mask)
    return mask


@jit
def advance(prob, cfg, c, x, v, a, w, istate, fstate, out):
    """Standard (or, after an event, refined) steps in configuration c while nothing happens: the hot loop.

    Stops, without taking it, at the first step that would reach the next grid
    point from off the grid, end past the chunk, cross an output instant,
    change a monitor's sign or leave the divergence limit; :func:`run_chunk` then takes that step with
    full handling. Kept small so numba can prune its reference counting.
    """
    ncl = prob.cl_ahead.shape[0]
    dt = prob.dt
    fine = dt / prob.refine
    while True:
        t = fstate[F_T]
        k_grid = istate[I_GRID]
        on_grid = t == k_grid * dt
        if t < fstate[F_FINE_UNTIL]:  # refined steps after an event, up to the next grid point
            h = fine
            if t + h >= (k_grid + 1) * dt:
                return
        elif on_grid:
            h = dt
        else:
            return
        if t + h > prob.t_end or t >= fstate[F_CHUNK_END]:
            return
        if prob.every_step or istate[I_NEXT_OUT] * prob.out_dt <= t + h + 1e-9 * dt:
            return
        newmark_step(prob, cfg, c, t, h, cfg.Sinv[c] if h == dt else cfg.SinvFine[c], x, v, a, w,
                     w.x1, w.v1, w.a1)
        fill_sources(prob, t + h, w.src)  # once per step
        for k in range(ncl):  # monitor() written out: numba runs this loop four times faster so
            if c & prob.cl_bit[k]:
                w.phi[k] = contact_force(prob, cfg, c, k, w.x1, w.v1, w.a1, w.src)
            elif prob.cl_monitored[k]:
                w.phi[k] = gap(prob, k, w.x1, w.src) + prob.gap_noise
            if prob.cl_monitored[k] and w.phi[k] < 0.0:
                return
        for i in range(prob.n):
            if not (abs(w.x1[i]) <= prob.x_limit):
                return
        for k in range(ncl):
            if c & prob.cl_bit[k] and w.phi[k] > out.F_peak[k]:
                out.F_peak[k] = w.phi[k]
        for i in range(prob.n):
            x[i] = w.x1[i]
            v[i] = w.v1[i]
            a[i] = w.a1[i]
        istate[I_STEPS] += 1
        if h == dt:
            istate[I_GRID] = k_grid + 1
            fstate[F_T] = (k_grid + 1) * dt
        else:
            fstate[F_T] = t + h


@jit
def run_chunk(prob, cfg, out, w, x, v, a, istate, fstate, codes):
    """Integrate from fstate[F_T] until t_end, the chunk end, or something Python must do.

    ``codes`` = (FINISHED, CHUNK_END, NEED_CONFIG, OUTPUT_FULL, DIVERGED,
    CHATTER): the status returned. (x, v, a) is the full state at fstate[F_T]
    in configuration istate[I_CFG]; everything needed to resume is in the
    arguments, so Python may build a configuration or grow a buffer and
    call again.
    """
    FINISHED, CHUNK_END, NEED_CONFIG, OUTPUT_FULL, DIVERGED, CHATTER = codes
    ncl = prob.cl_ahead.shape[0]
    n = prob.n
    closing = np.zeros(ncl, dtype=np.int64)
    while True:
        t = fstate[F_T]
        c = istate[I_CFG]
        if not cfg.built[c]:
            istate[I_WANT_CFG] = c
            return NEED_CONFIG
        if istate[I_NEED_ACCEL]:
            consistent_acceleration(prob, cfg, c, t, x, v, a, w.xl, w.vl, w.al, w.rhs)
            istate[I_NEED_ACCEL] = 0
            if istate[I_NOUT] == 0 and istate[I_NEXT_OUT] == 0:
                record(prob, cfg, c, t, x, v, a, w, out, 0)
                for k in range(ncl):  # the start counts for the peaks too
                    out.F_peak[k] = max(out.F_peak[k], out.F[0, k])
                istate[I_NOUT] = 1
                istate[I_NEXT_OUT] = 1
        if t >= prob.t_end - 1e-9 * prob.dt:
            return FINISHED
        if t >= fstate[F_CHUNK_END]:
            return CHUNK_END
        if istate[I_NEV] + 2 * ncl >= out.ev_t.shape[0]:  # room for the events of one step
            return OUTPUT_FULL
        advance(prob, cfg, c, x, v, a, w, istate, fstate, out)
        t = fstate[F_T]
        if t >= prob.t_end - 1e-9 * prob.dt:
            return FINISHED
        if t >= fstate[F_CHUNK_END]:
            return CHUNK_END
        grid_next = (istate[I_GRID] + 1) * prob.dt
        if t == istate[I_GRID] * prob.dt:  # on the grid: a standard step (exactly dt)
            h = min(prob.dt, prob.t_end - t)
        else:  # after an event: the rest of the step, back onto the grid
            h = min(grid_next, prob.t_end) - t
        if t < fstate[F_FINE_UNTIL]:  # just after an event: refined steps
            h = min(h, prob.dt / prob.refine)
        if h <= 1e-9 * prob.dt:  # already on the grid point
            istate[I_GRID] += 1
            fstate[F_T] = istate[I_GRID] * prob.dt
            continue
        step_to(prob, cfg, c, t, h, x, v, a, w, w.x1, w.v1, w.a1)
        fill_sources(prob, t + h, w.src)
        fired = False
        for k in range(ncl):
            w.tau[k] = 2.0 * h
            if prob.cl_monitored[k]:
                w.phi[k] = monitor(prob, cfg, c, k, w.x1, w.v1, w.a1, w.src)
                if w.phi[k] < 0.0:
                    fired = True
        if fired:  # locate every sign change; the earliest is taken
            tau_min = 2.0 * h
            for k in range(ncl):
                if prob.cl_monitored[k] and w.phi[k] < 0.0:
                    gather(cfg, c, x, v, a, w.xl, w.vl, w.al)
                    set_prescribed(prob, cfg, c, t, w.xl, w.vl, w.al)
                    fill_sources(prob, t, w.src)
                    phi0 = monitor(prob, cfg, c, k, x, v, a, w.src)
                    lo = 0.0
                    if phi0 < 0.0:
                        w.tau[k] = lo
                    else:
                        w.tau[k] = locate_event(prob, cfg, c, k, t, lo, h, phi0, w.phi[k], x, v, a, w)
                    tau_min = min(tau_min, w.tau[k])
            h = tau_min
            if h > 0.0:
                step_to(prob, cfg, c, t, h, x, v, a, w, w.x1, w.v1, w.a1)
            else:
                w.x1[:] = x
                w.v1[:] = v
                w.a1[:] = a
        # accept the (sub)step: peak forces at its end, outputs inside it
        if h > 0.0:
            for k in range(ncl):
                if c & prob.cl_bit[k]:
                    f = w.phi[k]  # the monitor already holds it (unless an event moved the step end)
                    if fired or not prob.cl_monitored[k]:
                        fill_sources(prob, t + h, w.src)
                        f = contact_force(prob, cfg, c, k, w.x1, w.v1, w.a1, w.src)
                    if f > out.F_peak[k]:
                        out.F_peak[k] = f
        w.x0[:] = x
        w.v0[:] = v
        w.a0[:] = a
        if h > 0.0:
            due = prob.every_step or istate[I_NEXT_OUT] * prob.out_dt <= t + h + 1e-9 * prob.dt
            if due and not record_outputs(prob, cfg, c, t, h, istate, out, w):
                return OUTPUT_FULL
            istate[I_STEPS] += 1
        x[:] = w.x1
        v[:] = w.v1
        a[:] = w.a1
        t = t + h
        fstate[F_T] = t
        if abs(t - grid_next) <= 1e-9 * prob.dt:
            istate[I_GRID] += 1
            fstate[F_T] = grid_next
            t = grid_next
        for i in range(n):
            if not (abs(x[i]) <= prob.x_limit):
                return DIVERGED
        if not fired:
            continue
        # the events at the earliest time (within the tolerance)
        new_c = c
        any_closing = False
        for k in range(ncl):
            closing[k] = 0
            if prob.cl_monitored[k] and w.tau[k] <= h + prob.time_tol:
                if c & prob.cl_bit[k]:
                    new_c &= ~prob.cl_bit[k]
                else:
                    closing[k] = 1
                    any_closing = True
        rapid = t - fstate[F_LAST_EVENT] <= prob.zeno_window
        istate[I_RAPID] = istate[I_RAPID] + 1 if rapid else 0
        fstate[F_LAST_EVENT] = t
        if istate[I_RAPID] >= prob.zeno_stop:
            return CHATTER
        stick = istate[I_RAPID] >= prob.zeno_stick
        for k in range(ncl):
            if (c & prob.cl_bit[k]) and not (new_c & prob.cl_bit[k]):
                add_event(out, istate, t, k, 0, 0.0, c, new_c)
        if any_closing:
            new_c = impact(prob, new_c, closing, t, x, v, stick, out, istate)
        istate[I_CFG] = new_c
        istate[I_NEED_ACCEL] = 1
        fstate[F_FINE_UNTIL] = t + prob.refine_window


@jit
def solve_impulse_lcp(W, u, b, eq, scale):
    """Impulses P >= 0 with u + W P - b >= 0 and complementarity (equalities: = b).

    Enumerates active sets, most contacts first; W is positive definite, so
    exactly one set satisfies the conditions (to the tolerance ``scale``).
    Returns (P, u⁺).
    """
    nc = u.shape[0]
    for pattern in range(2**nc - 1, -1, -1):
        Pt = np.zeros(nc)
        active = np.zeros(nc, dtype=np.int64)
        na = 0
        for r in range(nc):
            if eq[r] or (pattern >> r) & 1:
                active[na] = r
                na += 1
        if na > 0:
            Wa = np.empty((na, na))
            ra = np.empty(na)
            for p in range(na):
                ra[p] = b[active[p]] - u[active[p]]
                for q in range(na):
                    Wa[p, q] = W[active[p], active[q]]
            sol = np.linalg.solve(Wa, ra)
            for p in range(na):
                Pt[active[p]] = sol[p]
        ut = u + W @ Pt
        ok = True
        for r in range(nc):
            if not eq[r] and (Pt[r] * W[r, r] < -10.0 * scale or ut[r] - b[r] < -10.0 * scale):
                ok = False
        if ok:
            return Pt, ut
    return np.zeros(nc), u.copy()
