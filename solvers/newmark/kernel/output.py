"""The run's output: rows at the output instants (interpolated inside a step), and the peak forces."""

from __future__ import annotations

from vtool.jit import jit
from vtool.solvers.newmark.kernel.forces import compliant_force, rigid_force
from vtool.solvers.newmark.kernel.step import interpolate, prescribed, sources
from vtool.solvers.newmark.layout import (
    CI_HEAD,
    CI_NF,
    FP_DT,
    FP_GAPNOISE,
    FP_OUTDT,
    FP_TEND,
    I_NEXT_OUT,
    I_NOUT,
    IP_N,
    IP_NS,
    MK_FORCE,
    MK_KIND,
    MK_OVERLAP,
    PEAK_ALL,
    PEAK_LATE,
    PEAK_OVERLAP,
)


@jit
def record_row(prob, C, t, y, src, O, row, hertz):
    """Output row ``row``: time, configuration, the full coordinates (x, v, a planes) and the sources,
    and every clearance's contact force (0 when open)."""
    n, ns = prob.ip[IP_N], prob.ip[IP_NS]
    O.t[row] = t
    O.c[row] = C.mask
    for i in range(n):
        j = C.ci[CI_HEAD + n + i]
        O.q[0, row, i] = y.z[j]
        O.q[1, row, i] = y.zd[j]
        O.q[2, row, i] = y.zdd[j]
    for s in range(ns):
        O.q[0, row, n + s] = src[3 * s]
        O.q[1, row, n + s] = src[3 * s + 1]
        O.q[2, row, n + s] = src[3 * s + 2]
    for k in range(prob.cl.shape[0]):
        if C.mk[k, MK_KIND] == MK_FORCE:
            O.F[row, k] = rigid_force(prob, C, k, y, src, hertz)
        elif C.mk[k, MK_KIND] == MK_OVERLAP:
            O.F[row, k] = compliant_force(prob, C, k, y, src, hertz)
        else:
            O.F[row, k] = 0.0


@jit
def step_rows(prob, C, t, h, y, zdd1, W, O, S, hertz):
    """The output rows inside (t, t + h] of a step from y whose end acceleration is z̈1, by the
    linear-acceleration interpolant (exact for beta = 1/6; thesis eqs. B.3–B.5); False when the buffer
    filled first (the rows before are written)."""
    dt, t_end, out_dt = prob.fp[FP_DT], prob.fp[FP_TEND], prob.fp[FP_OUTDT]
    n = prob.ip[IP_N]
    ist = S.ist
    while True:
        j_out = ist[I_NEXT_OUT]
        t_out = j_out * out_dt
        if t_out > t + h + 1e-9 * dt or t_out > t_end + 1e-9 * dt:
            return True
        if ist[I_NOUT] >= O.t.shape[0]:
            return False
        interpolate(C.ci[CI_NF], t_out - t, h, y, zdd1, W.out)
        sources(prob, t_out, W.srco)
        prescribed(C.ci, n, W.srco, W.out.z, W.out.zd, W.out.zdd)
        record_row(prob, C, t_out, W.out, W.srco, O, ist[I_NOUT], hertz)
        ist[I_NOUT] += 1
        ist[I_NEXT_OUT] = j_out + 1


@jit
def track_peaks(prob, C, after, phi, y, src, peak, hertz):
    """Raise the peak contact forces (and compliant overlaps) with the monitors ``phi`` at a step's end
    (state y, sources src); ``after``: the step ends after the first cam revolution."""
    gap_noise = prob.fp[FP_GAPNOISE]
    for k in range(prob.cl.shape[0]):
        kind = C.mk[k, MK_KIND]
        force = phi[k]
        if kind == MK_OVERLAP:
            force = compliant_force(prob, C, k, y, src, hertz)
            peak[PEAK_OVERLAP, k] = max(peak[PEAK_OVERLAP, k], phi[k] - gap_noise)
        elif kind != MK_FORCE:
            continue
        peak[PEAK_ALL, k] = max(peak[PEAK_ALL, k], force)
        if after:
            peak[PEAK_LATE, k] = max(peak[PEAK_LATE, k], force)

