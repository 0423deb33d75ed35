"""The quiet loop: standard and refined steps in one configuration while nothing happens.

Most of a run's steps are taken here (:func:`advance`), so each is the least
work a step can be: the sources by rotation of the cam angle, the predictor,
one product with the stored step operator (which also gives the closed rigid
contacts' forces: ``layout.CP_RAW``), the corrector, the gap and force
checks and the peaks. The predictor, corrector, harmonics and gap checks are
the inline helpers every step shares (:mod:`~vtool.solvers.newmark.kernel.step`,
:mod:`~vtool.solvers.newmark.kernel.forces`); output rows are written by
:func:`~vtool.solvers.newmark.kernel.output.step_rows` when one is due.
"""

from __future__ import annotations

import math

from vtool.jit import jit
from vtool.solvers.newmark import layout
from vtool.solvers.newmark.kernel.algebra import apply_operator
from vtool.solvers.newmark.kernel.forces import signed_gap
from vtool.solvers.newmark.kernel.output import raise_peaks, step_rows
from vtool.solvers.newmark.kernel.step import corrected, harmonics, predict, prescribed

#: Quiet steps between fresh evaluations of cos and sin of the cam angle (see :func:`advance`).
ANCHOR_STEPS = 64


@jit
def advance(prob, C, W, S, O):
    """Standard and refined steps in configuration C from W.y[Y_NOW] while nothing happens; returns the time
    reached (the state there in W.y[Y_NOW]).

    It stops, without taking it, at the first step that is neither a
    standard step on the grid nor a refined one, that would end past the
    chunk or the run, change a monitor's sign, leave the divergence limit or
    overflow the output buffer; :func:`~vtool.solvers.newmark.kernel.loop.run_chunk`
    takes that step with full handling. Not called in every-step mode, nor in
    a configuration with closed Hertz contacts (each of their steps goes
    through layer_step's iteration). So its forces are the linear ones under
    every law pair: it takes no ``hertz`` switch, and numba compiles it once for
    all the kernels of :func:`~vtool.solvers.newmark.layout.laws` (the Hertz
    kernel loads it from the cache when a linear one compiled it first).

    Every array is taken out of its record once, before the loop: numba counts references, and a
    record's field read inside the loop would take and drop one at every step. The step's end is
    computed into W.y[Y_END] and copied back into W.y[Y_NOW], cheaper than swapping the two: the
    whole (3, n) block as one run of values, which compiles to vector copies (a loop over the m entries of
    three rows did not: LLVM's vector loop for three arrays needs more entries than a layer has).
    """
    ip, fp, ist, fst = prob.ip, prob.fp, S.ist, S.fst
    series, cl, clf = prob.series, prob.cl, prob.clf
    ci, cp, mk, mon = C.ci, C.cp, C.mk, C.mon
    now, end = W.y[layout.Y_NOW], W.y[layout.Y_END]
    now_values, end_values = now.reshape(now.size), end.reshape(end.size)  # (views: the rows are contiguous)
    state_size = now.size
    z, zd, zdd = now[layout.Z], now[layout.ZD], now[layout.ZDD]
    z1, zd1, zdd1 = end[layout.Z], end[layout.ZD], end[layout.ZDD]
    rhs, phi, src1, peak = W.system[layout.RHS], W.cross[layout.PHI], W.src[layout.SRC_END], O.peak
    Y, srco = W.y, W.src[layout.SRC_OUT]
    n, ns, ncl = ip[layout.IP_N], ip[layout.IP_NS], cl.shape[0]
    beta, gamma, dt, t_end = fp[layout.FP_BETA], fp[layout.FP_GAMMA], fp[layout.FP_DT], fp[layout.FP_TEND]
    out_dt, omega, gap_noise = fp[layout.FP_OUTDT], fp[layout.FP_OMEGA], fp[layout.FP_GAPNOISE]
    x_limit, t_rev = fp[layout.FP_XLIM], fp[layout.FP_TREV]
    refine = int(fp[layout.FP_REFINE] + 0.5)
    fine = dt / refine
    m, nf, nrows, coupled = ci[layout.CI_M], ci[layout.CI_NF], ci[layout.CI_ROWS], ci[layout.CI_SRCSTEP]
    constant = 3 * n + 3 * ns  # a force row's constant term, in its monitor row
    t = fst[layout.F_T]
    # cos, sin of omega t, carried from step to step by the rotation through one step's angle (libm's
    # sincos took a seventh of a quiet step), and taken afresh every ANCHOR_STEPS steps: the rotation's
    # round-off grows by an ulp or two a step, so they stay within about 1e-13 of libm's, the round-off
    # of the angle omega t itself at a few hundred rad
    c0 = math.cos(omega * t)
    s0 = math.sin(omega * t)
    c_dt = math.cos(omega * dt)
    s_dt = math.sin(omega * dt)
    c_fine = math.cos(omega * fine)
    s_fine = math.sin(omega * fine)
    rotated = 0
    t_out = ist[layout.I_NEXT_OUT] * out_dt  # the next output instant (moved on only by step_rows)
    # the grid position and the step count in locals, stored once when the loop ends (a store to the
    # state array and its load at the next step's start went through memory: numba's arrays may alias)
    k_grid, sub, steps = ist[layout.I_GRID], ist[layout.I_SUB], ist[layout.I_STEPS]
    fine_until, chunk_end = fst[layout.F_FINE_UNTIL], fst[layout.F_CHUNK_END]
    while True:
        if sub > 0 or t < fine_until:  # refined steps on their grid, on to the next grid point
            if t != k_grid * dt + sub * fine:
                break
            h = fine
            plane = layout.CP_FINE
            t1 = (k_grid + 1) * dt if sub + 1 == refine else k_grid * dt + (sub + 1) * fine
        elif t == k_grid * dt:
            h = dt
            plane = layout.CP_STD
            t1 = (k_grid + 1) * dt
        else:
            break
        if t1 > t_end or t >= chunk_end:
            break
        if rotated == ANCHOR_STEPS:
            c1 = math.cos(omega * t1)
            s1 = math.sin(omega * t1)
        elif plane == layout.CP_STD:
            c1 = c0 * c_dt - s0 * s_dt
            s1 = s0 * c_dt + c0 * s_dt
        else:
            c1 = c0 * c_fine - s0 * s_fine
            s1 = s0 * c_fine + c0 * s_fine
        # the step (layer_step's, with the stored operator: its force rows give the contact forces too)
        harmonics(series, omega, c1, s1, src1)
        predict(m, h, beta, gamma, z, zd, zdd, z1, zd1)
        prescribed(ci, n, src1, z1, zd1, zdd1)
        apply_operator(cp, ci, plane, nrows, coupled, src1, z1, zd1, zdd1, rhs)
        # the corrector (step.correct's, on scalars: see step.corrected), the divergence limit checked on
        # each corrected value as it is stored (a vector load of z1 after these scalar stores would wait)
        bx = beta * h * h
        gv = gamma * h
        within = True
        for f in range(nf):
            a = rhs[f]
            zdd1[f] = a
            zf, zdf = corrected(a, z1[f], zd1[f], bx, gv)
            z1[f] = zf
            zd1[f] = zdf
            within &= abs(zf) <= x_limit
        if not within:  # past the divergence limit
            break
        stop = False
        for k in range(ncl):  # monitors (see forces.monitors): stop before a sign change
            kind = mk[k, layout.MK_KIND]
            value = 0.0
            if kind == layout.MK_GAP or kind == layout.MK_OVERLAP:
                behind = mk[k, layout.MK_BEHIND]
                other = z1[behind] if behind >= 0 else src1[3 * (-1 - behind)]
                gap = clf[k, layout.CLF_SIGN] * (z1[mk[k, layout.MK_AHEAD]] - other) + clf[k, layout.CLF_OPEN]
                value = signed_gap(kind, gap, gap_noise)
                stop |= value < 0.0
            elif kind == layout.MK_FORCE:  # its force row of the step's product, and the row's constant
                value = mon[k, constant] + rhs[mk[k, layout.MK_ROW]]
                stop |= value < 0.0 and cl[k, layout.CL_MON] != 0
            phi[k] = value
        if stop:
            break
        if t_out <= t1 + 1e-9 * dt and t_out <= t_end + 1e-9 * dt:  # output rows inside (t, t1]
            if not step_rows(prob, C, t, h, Y, srco, O, ist, None):  # (no closed Hertz contact: see above)
                break
            t_out = ist[layout.I_NEXT_OUT] * out_dt
        # accept: peaks (the rigid contacts' forces from the step's product), state, time
        raise_peaks(mk, mon, n, ns, t1 >= t_rev, gap_noise, phi, z1, zd1, zdd1, src1, peak)
        for j in range(state_size):  # the whole (3, n) block as one run of values (vector copies)
            now_values[j] = end_values[j]
        steps += 1
        if plane == layout.CP_STD or sub + 1 == refine:
            k_grid += 1
            sub = 0
        else:
            sub += 1
        t = t1
        c0 = c1
        s0 = s1
        rotated = 0 if rotated == ANCHOR_STEPS else rotated + 1
    ist[layout.I_GRID], ist[layout.I_SUB], ist[layout.I_STEPS] = k_grid, sub, steps
    fst[layout.F_T] = t
    return t
