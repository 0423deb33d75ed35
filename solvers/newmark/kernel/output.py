"""The run's output: rows at the output instants (interpolated inside a step), and the peak forces."""

from __future__ import annotations

import math

from vtool.jit import jit, jit_inline
from vtool.solvers.newmark import layout
from vtool.solvers.newmark.kernel.forces import compliant_force, linear_force, rigid_force
from vtool.solvers.newmark.kernel.step import harmonics, interpolate, prescribed


@jit_inline
def put_state(ci, n, ns, row, z, zd, zdd, src, q):
    """Row ``row`` of the output planes q (x, v, a): the full coordinates of the layer state
    (z, ż, z̈) in the configuration whose integer row is ci, then the sources."""
    for i in range(n):
        j = ci[layout.CI_HEAD + n + i]
        q[0, row, i] = z[j]
        q[1, row, i] = zd[j]
        q[2, row, i] = zdd[j]
    for s in range(ns):
        q[0, row, n + s] = src[3 * s]
        q[1, row, n + s] = src[3 * s + 1]
        q[2, row, n + s] = src[3 * s + 2]


@jit
def record_row(prob, C, t, y, src, O, row, hertz):
    """Output row ``row``: time, configuration, the full coordinates (x, v, a planes) and the sources,
    and every clearance's contact force (0 when open)."""
    n, ns = prob.ip[layout.IP_N], prob.ip[layout.IP_NS]
    O.t[row] = t
    O.c[row] = C.mask
    put_state(C.ci, n, ns, row, y[layout.Z], y[layout.ZD], y[layout.ZDD], src, O.q)
    for k in range(prob.cl.shape[0]):
        kind = C.mk[k, layout.MK_KIND]
        force = 0.0
        if hertz is None:  # (with no Hertz contact, a closed contact's force is its linear row)
            if kind == layout.MK_FORCE or kind == layout.MK_OVERLAP:
                force = linear_force(C.mon, k, n, ns, C.mk[k, layout.MK_M], y[layout.Z], y[layout.ZD], y[layout.ZDD],
                                     src)
        elif kind == layout.MK_FORCE:
            force = rigid_force(prob, C, k, y, src, hertz)
        elif kind == layout.MK_OVERLAP:
            force = compliant_force(prob, C, k, y, src, hertz)
        O.F[row, k] = force


@jit
def step_rows(prob, C, t, h, Y, srco, O, ist, hertz):
    """The output rows inside (t, t + h] of a step from the layer state Y[Y_NOW] whose end acceleration
    is Y[Y_END, ZDD] (Y: the scratch's layer states), by the linear-acceleration interpolant (exact for
    beta = 1/6; thesis eqs. B.3–B.5), each row's state in Y[Y_OUT] and its sources in srco; False when
    the buffer filled first (the rows before are written). :func:`record_row`'s row, on arrays taken
    out of the records once. It is handed only what it uses, not the scratch and state records: a
    non-inline call passes every array of its records, field by field (less code to compile)."""
    fp = prob.fp
    dt, t_end, out_dt, omega = fp[layout.FP_DT], fp[layout.FP_TEND], fp[layout.FP_OUTDT], fp[layout.FP_OMEGA]
    n, ns, ncl = prob.ip[layout.IP_N], prob.ip[layout.IP_NS], prob.cl.shape[0]
    series = prob.series
    ci, mk, mon = C.ci, C.mk, C.mon
    y, out, zdd1 = Y[layout.Y_NOW], Y[layout.Y_OUT], Y[layout.Y_END, layout.ZDD]
    z, zd, zdd = y[layout.Z], y[layout.ZD], y[layout.ZDD]
    zo, zdo, zddo = out[layout.Z], out[layout.ZD], out[layout.ZDD]
    out_t, out_q, out_F, out_c = O.t, O.q, O.F, O.c
    nf = ci[layout.CI_NF]
    while True:
        j_out = ist[layout.I_NEXT_OUT]
        t_out = j_out * out_dt
        if t_out > t + h + 1e-9 * dt or t_out > t_end + 1e-9 * dt:
            return True
        row = ist[layout.I_NOUT]
        if row >= out_t.shape[0]:
            return False
        interpolate(nf, t_out - t, h, z, zd, zdd, zdd1, out)
        harmonics(series, omega, math.cos(omega * t_out), math.sin(omega * t_out), srco)
        prescribed(ci, n, srco, zo, zdo, zddo)
        out_t[row] = t_out
        out_c[row] = C.mask
        put_state(ci, n, ns, row, zo, zdo, zddo, srco, out_q)
        for k in range(ncl):
            kind = mk[k, layout.MK_KIND]
            force = 0.0
            if hertz is None:  # (the branches below are pruned before typing: see layout.laws)
                if kind == layout.MK_FORCE or kind == layout.MK_OVERLAP:
                    force = linear_force(mon, k, n, ns, mk[k, layout.MK_M], zo, zdo, zddo, srco)
            elif kind == layout.MK_FORCE:
                force = rigid_force(prob, C, k, out, srco, hertz)
            elif kind == layout.MK_OVERLAP:
                force = compliant_force(prob, C, k, out, srco, hertz)
            out_F[row, k] = force
        ist[layout.I_NOUT] = row + 1
        ist[layout.I_NEXT_OUT] = j_out + 1


@jit_inline
def raise_peaks(mk, mon, n, ns, after, gap_noise, phi, z, zd, zdd, src, peak):
    """:func:`track_peaks` with linear contacts only (no Hertz law): a closed rigid contact's force is
    its monitor phi[k], a compliant one's its linear row at the step's end (z, ż, z̈, sources src)."""
    for k in range(phi.shape[0]):
        kind = mk[k, layout.MK_KIND]
        if kind == layout.MK_FORCE:
            force = phi[k]
        elif kind == layout.MK_OVERLAP:
            force = linear_force(mon, k, n, ns, mk[k, layout.MK_M], z, zd, zdd, src)
            peak[layout.PEAK_OVERLAP, k] = max(peak[layout.PEAK_OVERLAP, k], phi[k] - gap_noise)
        else:
            continue
        peak[layout.PEAK_ALL, k] = max(peak[layout.PEAK_ALL, k], force)
        if after:
            peak[layout.PEAK_LATE, k] = max(peak[layout.PEAK_LATE, k], force)


@jit
def track_peaks(prob, C, after, phi, y, src, peak, hertz):
    """Raise the peak contact forces (and compliant overlaps) with the monitors ``phi`` at a step's end
    (state y, sources src); ``after``: the step ends after the first cam revolution. A compliant
    contact's force by its own law (:func:`compliant_force`): the run loop calls this with Hertz
    contacts, :func:`raise_peaks` with linear ones."""
    gap_noise = prob.fp[layout.FP_GAPNOISE]
    mk = C.mk
    for k in range(prob.cl.shape[0]):
        kind = mk[k, layout.MK_KIND]
        force = phi[k]
        if kind == layout.MK_OVERLAP:
            force = compliant_force(prob, C, k, y, src, hertz)
            peak[layout.PEAK_OVERLAP, k] = max(peak[layout.PEAK_OVERLAP, k], phi[k] - gap_noise)
        elif kind != layout.MK_FORCE:
            continue
        peak[layout.PEAK_ALL, k] = max(peak[layout.PEAK_ALL, k], force)
        if after:
            peak[layout.PEAK_LATE, k] = max(peak[layout.PEAK_LATE, k], force)
