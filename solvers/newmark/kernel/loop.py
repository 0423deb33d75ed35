"""The run loop: steps in a configuration until an event, event location, and the chunked entry point."""

from __future__ import annotations

import math

from vtool.jit import borrowed, jit, jit_inline
from vtool.solvers.newmark import layout
from vtool.solvers.newmark.kernel.forces import (
    linear_force,
    monitors,
    rigid_force,
    signed_gap,
)
from vtool.solvers.newmark.kernel.impacts import release_pulling, take_events
from vtool.solvers.newmark.kernel.output import raise_peaks, record_row, step_rows, track_peaks
from vtool.solvers.newmark.kernel.quiet import advance
from vtool.solvers.newmark.kernel.step import (
    CHOLESKY,
    REFINED,
    STANDARD,
    configuration,
    find_slot,
    gather,
    layer_step,
    scatter,
    sources,
)
from vtool.solvers.newmark.records import Output, Problem, Scratch, State, Tables


@jit
def locate_event(prob, C, W, k, t, h, hertz):
    """Earliest tau in (0, h] where monitor k crosses zero, re-stepping from W.y[Y_NOW] at t.

    Illinois (modified regula falsi) on phi(tau) = monitor after a Newmark
    step of length tau, bracketed by phi(0) = W.cross[PHI_START, k] >= 0 > phi(h) =
    W.cross[PHI, k], with a bisection whenever two iterations have not halved the
    bracket; returns the left end of the final bracket (the monitor still
    non-negative), within the time tolerance of the crossing, or its right end
    when the left is the step's start (a bracket narrower than the tolerance
    from the start: a step shorter than it, or a crossing within it): an
    event at tau = 0 would make no progress, and a contact released at t
    whose gap the round-off closes again within the tolerance would close and
    open at t until the chattering stop. Each trial is a step of length tau
    (S(tau) factored by Cholesky): the same code as the event's step, compiled
    once in :func:`~vtool.solvers.newmark.kernel.step.layer_step` (a copy of it
    here cost about 0.6 s of first compile; the call costs about 1 % of a run).
    """
    fp, ip = prob.fp, prob.ip
    tol, gap_noise = fp[layout.FP_TTOL], fp[layout.FP_GAPNOISE]
    n, ns = ip[layout.IP_N], ip[layout.IP_NS]
    clf, mk, mon = prob.clf, C.mk, C.mon
    end = W.y[layout.Y_END]
    z1, zd1, zdd1 = end[layout.Z], end[layout.ZD], end[layout.ZDD]
    src1 = W.src[layout.SRC_END]
    kind = mk[k, layout.MK_KIND]
    lo, hi = 0.0, h
    flo, fhi = W.cross[layout.PHI_START, k], W.cross[layout.PHI, k]
    side = 0
    width_before = 2.0 * h
    for iteration in range(200):
        width = hi - lo
        if width <= tol:
            break
        if iteration % 2 == 0:
            if width > 0.5 * width_before:
                tau = 0.5 * (lo + hi)
            else:
                tau = (lo * fhi - hi * flo) / (fhi - flo)
            width_before = width
        else:
            tau = (lo * fhi - hi * flo) / (fhi - flo)
        tau = min(max(tau, lo + 0.25 * tol), hi - 0.25 * tol)
        # the trial step from t: sources at t + tau, a step of length tau (layer_step factors S(tau)); written
        # here, not as an inline helper of the records: its records' arrays were counted in and out at every trial
        sources(prob.series, fp[layout.FP_OMEGA], t + tau, W.src[layout.SRC_END])
        layer_step(prob, C, W, tau, CHOLESKY, hertz)
        # monitor k (see forces.monitors), on the arrays
        if kind == layout.MK_GAP or kind == layout.MK_OVERLAP:
            behind = mk[k, layout.MK_BEHIND]
            other = z1[behind] if behind >= 0 else src1[3 * (-1 - behind)]
            gap = clf[k, layout.CLF_SIGN] * (z1[mk[k, layout.MK_AHEAD]] - other) + clf[k, layout.CLF_OPEN]
            f = signed_gap(kind, gap, gap_noise)
        elif hertz is None:  # a closed rigid contact's force: the linear row alone
            f = linear_force(mon, k, n, ns, mk[k, layout.MK_M], z1, zd1, zdd1, src1)
        else:
            f = rigid_force(prob, C, k, end, src1, hertz)
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
    return lo if lo > 0.0 else hi


@jit_inline
def copy_state(m, y, src, y_to, src_to):
    """The first m entries of y, and the sources, into y_to and src_to."""
    for j in range(m):
        y_to[layout.Z, j] = y[layout.Z, j]
        y_to[layout.ZD, j] = y[layout.ZD, j]
        y_to[layout.ZDD, j] = y[layout.ZDD, j]
    for j in range(src.shape[0]):
        src_to[j] = src[j]


@jit_inline
def arrive(S, target, grid_next, k_grid, j_target):
    """Now at ``target``: the next standard grid point, or point ``j_target`` of the refined grid."""
    if target == grid_next:
        S.ist[layout.I_GRID] = k_grid + 1
        S.ist[layout.I_SUB] = 0
    else:
        S.ist[layout.I_SUB] = j_target
    S.fst[layout.F_T] = target
    return target


@jit_inline
def start(prob, C, W, S, O, hertz):
    """The run's first row (the start is an output row and counts for the peaks); False when the
    output buffer is full."""
    ist = S.ist
    if ist[layout.I_NOUT] >= O.t.shape[0]:
        return False
    gather(C, prob.ip[layout.IP_N], S, W.y[layout.Y_NOW])
    record_row(prob, C, S.fst[layout.F_T], W.y[layout.Y_NOW], W.src[layout.SRC_NOW], O, ist[layout.I_NOUT], hertz)
    for k in range(prob.cl.shape[0]):
        O.peak[layout.PEAK_ALL, k] = max(O.peak[layout.PEAK_ALL, k], O.F[ist[layout.I_NOUT], k])
    ist[layout.I_NOUT] += 1
    ist[layout.I_NEXT_OUT] = 1
    ist[layout.I_STARTED] = 1
    return True


@jit_inline
def step_length(prob, S, t, c_hertz):
    """The next step from t: (h, target, grid_next, j_target, quiet), quiet when the quiet loop may take it
    (on a point of the step grid, not every-step mode, no closed Hertz contact)."""
    fp, ist = prob.fp, S.ist
    dt, t_end = fp[layout.FP_DT], fp[layout.FP_TEND]
    refine = int(fp[layout.FP_REFINE] + 0.5)
    fine = dt / refine
    k_grid = ist[layout.I_GRID]
    sub = ist[layout.I_SUB]
    refined = sub > 0 or t < S.fst[layout.F_FINE_UNTIL]
    quiet = t == (k_grid * dt + sub * fine if refined else k_grid * dt) and not (prob.ip[layout.IP_EVERY] or c_hertz)
    grid_next = (k_grid + 1) * dt
    j_target = -1  # refined steps: the index of the refined grid point this step reaches
    target = grid_next
    if refined:
        if t == k_grid * dt + sub * fine:
            j_target = sub + 1
        else:  # after an event, between the refined grid's points: on to the next one
            j_target = int((t - k_grid * dt) / fine) + 1
        target = grid_next if j_target >= refine else k_grid * dt + j_target * fine
        h = min(target, t_end) - t
        if t == k_grid * dt + sub * fine and target <= t_end:
            h = fine
    elif t == k_grid * dt:
        h = min(dt, t_end - t)
    else:
        h = min(grid_next, t_end) - t
    return h, target, grid_next, j_target, quiet


@jit_inline
def event_step(prob, C, W, t, h, hertz):
    """After a step of length h whose monitors W.cross[PHI] changed sign: locate every sign change, take the
    earliest (tau in W.cross[TAU]) and redo the step to it. Returns the step taken."""
    ncl = prob.cl.shape[0]
    gap_noise = prob.fp[layout.FP_GAPNOISE]
    monitors(prob, C, W.y[layout.Y_NOW], W.src[layout.SRC_NOW], gap_noise, W.cross[layout.PHI_START], hertz)
    tau_min = 2.0 * h
    for k in range(ncl):
        # no crossing: never an event (take_events takes tau <= h + tol, also for h < tol)
        W.cross[layout.TAU, k] = math.inf
        if prob.cl[k, layout.CL_MON] and W.cross[layout.PHI, k] < 0.0:
            started_past = W.cross[layout.PHI_START, k] < 0.0
            W.cross[layout.TAU, k] = 0.0 if started_past else locate_event(prob, C, W, k, t, h, hertz)
            tau_min = min(tau_min, W.cross[layout.TAU, k])
    h = tau_min
    if h > 0.0:
        # the step to the earliest crossing (as locate_event's trials)
        sources(prob.series, prob.fp[layout.FP_OMEGA], t + h, W.src[layout.SRC_END])
        layer_step(prob, C, W, h, CHOLESKY, hertz)
        # (the gaps' values too: only the forces' and overlaps' are used, by the peaks)
        monitors(prob, C, W.y[layout.Y_END], W.src[layout.SRC_END], gap_noise, W.cross[layout.PHI], hertz)
    else:
        copy_state(prob.ip[layout.IP_N], W.y[layout.Y_NOW], W.src[layout.SRC_NOW], W.y[layout.Y_END],
                   W.src[layout.SRC_END])
    return h


@jit_inline
def borrow(prob, T, W, S, O):
    """The records with their arrays :func:`~vtool.jit.borrowed` (not reference-counted in the calls).

    All but four: the configuration index (read here only) and the full state x, v, a (records that
    carry them go to calls made once per quiet run or event, where a count costs nothing that shows),
    so that there is less code to compile (about 0.2 s of first compile)."""
    b = borrowed
    prob = Problem(b(prob.ip), b(prob.fp), b(prob.cl), b(prob.clf), b(prob.series), b(prob.mass))
    T = Tables(T.index, b(T.ci), b(T.cm), b(T.cp), b(T.mk), b(T.mon))
    W = Scratch(b(W.y), b(W.src), b(W.cross), b(W.system), b(W.L), b(W.closing))
    S = State(S.x, S.v, S.a, b(S.ist), b(S.fst))
    O = Output(b(O.t), b(O.q), b(O.F), b(O.c), b(O.ev_f), b(O.ev_i), b(O.peak))  # noqa: E741
    return prob, T, W, S, O


@jit
def run_chunk(prob, T, W, S, O, hertz, momentum):
    """Integrate from S.fst[F_T] until t_end, the chunk end, or something Python must do.

    Returns a status (FINISHED, CHUNK_END, NEED_CONFIG, OUTPUT_FULL, DIVERGED,
    CHATTER). (S.x, S.v, S.a) is the full state at S.fst[F_T] in configuration
    S.ist[I_CFG]; everything needed to resume is in the arguments, so Python
    may build a configuration (NEED_CONFIG: its mask in S.ist[I_WANT_CFG]) or
    empty a buffer and call again. Output rows at the output instants are
    interpolated inside the step; ``O.peak[PEAK_ALL]`` holds the peak contact
    forces over every step, ``[PEAK_LATE]`` those after the first cam
    revolution, ``[PEAK_OVERLAP]`` the largest overlap of each compliant
    contact. The caller zeroes the scratch W before each call, as fresh arrays would be, but one that goes
    on after a chunk's end (the kernel itself goes on there when ``prob.fp[FP_CHUNK]`` is set).
    Only the momentum law's impacts and the Hertz iteration allocate their
    small systems.
    """
    prob, T, W, S, O = borrow(prob, T, W, S, O)  # noqa: E741
    fp, ist, fst = prob.fp, S.ist, S.fst
    n, ncl = prob.ip[layout.IP_N], prob.cl.shape[0]
    dt, t_end, out_dt = fp[layout.FP_DT], fp[layout.FP_TEND], fp[layout.FP_OUTDT]
    x_limit, t_rev, omega = fp[layout.FP_XLIM], fp[layout.FP_TREV], fp[layout.FP_OMEGA]
    now, end, src0, src1 = W.y[layout.Y_NOW], W.y[layout.Y_END], W.src[layout.SRC_NOW], W.src[layout.SRC_END]
    phi = W.cross[layout.PHI]
    while True:
        t = fst[layout.F_T]
        c = ist[layout.I_CFG]
        if ist[layout.I_NEV] + 3 * ncl + 2 >= O.ev_f.shape[0]:
            return layout.OUTPUT_FULL
        sources(prob.series, omega, t, src0)
        if ist[layout.I_NEED_SETTLE]:  # (release_pulling asks for every configuration it reaches to be built)
            settled = release_pulling(prob, T, c, t, S, src0, O, now, W.system[layout.RHS], hertz)
            if settled < 0:
                ist[layout.I_CFG] = -1 - settled
                ist[layout.I_WANT_CFG] = -1 - settled
                return layout.NEED_CONFIG
            c = settled
            ist[layout.I_CFG] = c
            ist[layout.I_NEED_SETTLE] = 0
        slot = find_slot(T.index, c)
        if slot < 0:
            ist[layout.I_WANT_CFG] = c
            return layout.NEED_CONFIG
        C = configuration(T, c, slot)
        if not ist[layout.I_STARTED] and not start(prob, C, W, S, O, hertz):
            return layout.OUTPUT_FULL
        gather(C, n, S, now)
        # ---- steps in configuration C until an event (status 0), the chunk end, the run's end or a full
        # buffer (written here, not as an inline function: numba copies an inline function's whole IR
        # at its call, a cost that grows with its blocks times its variables) ----
        h = 0.0
        status = 0
        while True:
            if t >= t_end - 1e-9 * dt:
                status = layout.FINISHED
                break
            if t >= fst[layout.F_CHUNK_END]:
                status = layout.CHUNK_END
                break
            h, target, grid_next, j_target, quiet = step_length(prob, S, t, C.ci[layout.CI_HERTZ])
            if quiet:  # quiet steps may follow; off the grid, after an event, the call would return at once
                t_quiet = advance(prob, C, W, S, O)
                if t_quiet != t:  # quiet steps taken: sources at the new time, then the end checks again
                    t = t_quiet
                    sources(prob.series, omega, t, src0)
                    continue
            if h <= 1e-9 * dt:  # at a grid point but for round-off
                t = arrive(S, target, grid_next, ist[layout.I_GRID], j_target)
                continue
            sources(prob.series, omega, t + h, src1)
            which = STANDARD
            if h != dt:
                which = REFINED if h == dt / int(fp[layout.FP_REFINE] + 0.5) else CHOLESKY
            layer_step(prob, C, W, h, which, hertz)
            monitors(prob, C, end, src1, fp[layout.FP_GAPNOISE], phi, hertz)
            fired = False
            for k in range(ncl):
                if prob.cl[k, layout.CL_MON] and phi[k] < 0.0:
                    fired = True
            if fired:  # locate every sign change; the earliest is taken
                h = event_step(prob, C, W, t, h, hertz)
            if h > 0.0:
                for j in range(C.ci[layout.CI_NF]):
                    if not (abs(end[layout.Z, j]) <= x_limit):  # the state at the divergence into S
                        scatter(C, n, end, S)
                        fst[layout.F_T] = t + h
                        return layout.DIVERGED
                # outputs inside (t, t + h]
                if prob.ip[layout.IP_EVERY]:
                    if ist[layout.I_NOUT] >= O.t.shape[0]:
                        status = layout.OUTPUT_FULL
                        break
                    record_row(prob, C, t + h, end, src1, O, ist[layout.I_NOUT], hertz)
                    ist[layout.I_NOUT] += 1
                else:
                    t_out = ist[layout.I_NEXT_OUT] * out_dt  # the next output instant: a call only when one is due
                    if (t_out <= t + h + 1e-9 * dt and t_out <= t_end + 1e-9 * dt
                            and not step_rows(prob, C, t, h, W.y, W.src[layout.SRC_OUT], O, ist, hertz)):
                        status = layout.OUTPUT_FULL
                        break
                if hertz is None:  # linear contacts: the quiet loop's peaks (no call to compile)
                    raise_peaks(C.mk, C.mon, n, prob.ip[layout.IP_NS], t + h >= t_rev, fp[layout.FP_GAPNOISE], phi,
                                end[layout.Z], end[layout.ZD], end[layout.ZDD], src1, O.peak)
                else:
                    track_peaks(prob, C, t + h >= t_rev, phi, end, src1, O.peak, hertz)
                ist[layout.I_STEPS] += 1
                copy_state(n, end, src1, now, src0)
                t = t + h
                fst[layout.F_T] = t
                if abs(t - target) <= 1e-9 * dt:
                    t = arrive(S, target, grid_next, ist[layout.I_GRID], j_target)
            if fired:
                break
        scatter(C, n, now, S)
        if status == layout.CHUNK_END and fp[layout.FP_CHUNK] > 0.0:
            # no caller to report to: the next chunk as a new call would start it (KernelRun.execute)
            fst[layout.F_CHUNK_END] = fst[layout.F_T] + fp[layout.FP_CHUNK]
            continue
        if status != 0:
            return status
        # ---- the events at t (within the tolerance) ----
        t = fst[layout.F_T]
        new_c = take_events(prob, c, t, h, W, S, O, momentum)
        if new_c < 0:
            return layout.CHATTER
        ist[layout.I_CFG] = new_c
        ist[layout.I_NEED_SETTLE] = 1
        fst[layout.F_FINE_UNTIL] = t + prob.fp[layout.FP_REFWIN]
