"""Compiled Newmark integration of the valve train with clearances (numba).

Everything the run loop touches lives in this one module (the numba cache
misses edits in other files), except the arrays' slot numbers and codes, in
:mod:`vtool.solvers.newmark.layout` (numba-free, so that a run on the native
module imports no numba), whose digest :data:`LAYOUT_FINGERPRINT` repeats:
an edit there must change this file, and so the cache (a test checks).
The same source, run with ``NUMBA_DISABLE_JIT=1``, is the plain-NumPy reference the tests compare the
compiled kernel with. The arrays are built by :mod:`vtool.solvers.model.contact`
(the contact problem every back end shares); their layout is given by the
``IP_*``, ``FP_*``, ``CL_*``, ``CI_*``, ``CM_*`` and ``MK_*`` slot numbers
in :mod:`vtool.solvers.newmark.layout`.

Conventions
-----------
Full coordinates: the n elastic system coordinates q_1..q_n (0-based here).
Sources: prescribed motions as Fourier series (:mod:`vtool.solvers.model.sources`)
x_s(t) = c_s + Σ_k a_sk cos kωt + b_sk sin kωt. A configuration ``c`` is a
bit mask over the clearances (contact = 1). In configuration c the layer
vector z (size m) holds the full coordinates with every closed internal pair
tied, ordered **free first**: z[0:nf] are integrated, z[nf:m] are prescribed
(tied to a source through a closed external clearance). ``group`` maps a full
coordinate to its z index, ``kept`` a z index to one full coordinate.

Newmark step of length h in configuration c (general beta, gamma):

    z̃ = z + h ż + h²(1/2 - beta) z̈,   ż̃ = ż + h(1 - gamma) z̈
    S z̈_F = -C_FF ż̃_F - K_FF z̃_F - (M_FP z̈_P + C_FP ż_P + K_FP z_P)     (ΔP)
    S = M_FF + gamma h C_FF + beta h² K_FF          (thesis BMIV = S⁻¹)
    z_F = z̃_F + beta h² z̈_F,   ż_F = ż̃_F + gamma h z̈_F

with the prescribed values (z_P, ż_P, z̈_P) taken from the sources at t + h.
Standard and refined steps use stored products G = S⁻¹[C_FF | K_FF | ΔP's
other columns] (``CP_STD``, ``CP_FINE``): z̈_F = -G·(ż̃_F, z̃_F, …) is one
product, with no right-hand side formed first; other step lengths (event
location, the return to the step grid) form ΔP and factor S by Cholesky in
place.

Monitors: a closed clearance's contact force (a row of coefficients on
(z, ż, z̈, sources) per configuration, positive in compression), an open
one's gap q[ahead] - q[behind] (+ the round-off allowance). A sign change
is an event.

Impact laws (per clearance, ``CL_LAW``): ``LAW_MOMENTUM`` one linear
complementarity problem on the consistent mass matrix; ``LAW_LOCAL`` only the
impacting coordinate's velocity changes (external), or the two tied
coordinates take their common, momentum-conserving velocity computed with the
two diagonal masses (internal); ``LAW_THESIS`` as local but an internal
closing gives the tied pair SCALE times the ahead coordinate's velocity
(Gnilka eq. 3.54). See :func:`impact`.

After every transition :func:`settle` computes the consistent accelerations
of the new configuration and releases at once any contact whose force would
pull (an impact so released is a bounce: two events at one instant).

Compile time
------------
Entry points (``@jit``) get numba's CPython wrapper; functions only compiled
code calls (``@inner``) get none, and their code libraries are link-only
(:mod:`vtool.numba_link`). Each is compiled once and linked into its callers,
where LLVM inlines the small ones. Only :func:`apply_operator`, the quiet
step's product, is ``@tiny``: copied into its callers as numba IR, so that
LLVM vectorizes it in place (with it ``@inner`` too, the quiet step was 21 %
slower on 1A; numba's copies of the other helpers cost a sixth of the compile
and no run speed: ``bench_step_ab.py``, ``bench_compile_ab.py``). The
``hertz`` and ``momentum`` arguments (:func:`~vtool.solvers.newmark.layout.laws`) are None when no
clearance uses that law: numba then prunes the branches under them before
typing, so the Hertz iteration and the momentum-law LCP are compiled (and
cached) only for mechanisms that use them.

Reference counts: numba counts the references to every array a function
holds, with an atomic increment and decrement per array argument at each
call and per view it makes. The kernel's arrays all belong to the Python
caller for the whole call (``run_chunk``'s arguments, and views of them), so
``run_chunk`` and the ``@inner`` functions are compiled without numba's
reference counting (``_nrt=False``): their calls pass the same arrays with
no counting, and numba lowers and optimizes none of it (kernel 0.93 of the
counted one per step on 1A, first compile 0.92: ``bench_step_ab.py``,
``bench_compile_ab.py``). The functions that make arrays of their own (the
Hertz iteration, the momentum law's impacts: ``@allocating``) keep it, set
explicitly, since numba's default takes the caller's setting; what they make
is freed before they return, and an array they are handed is counted up and
down again inside them.

The event rules the piecewise back ends call
from Python (``settle``, ``impact``, ``fill_sources``, ``snap_shut``,
``relative_velocity``, ``hertz_law``) are entry points that only call an
``@inner`` function, which is what the kernel calls: a kernel compile then
makes no machine code for them (an entry point's library is finalized into
machine code of its own, which ``run_chunk`` never runs), and a piecewise
back end's compile of them links the cached inner functions.

Loaded a second time under the module name ``…newmark_kernel_plain``
(:data:`PLAIN`), the same source is plain Python, numba left out: a new
install's first run goes on in it while a child process compiles the kernel
into numba's cache (see :mod:`vtool.solvers.newmark.backend`, "First run").
"""

from __future__ import annotations

import math
import os
from typing import Any

import numpy as np

from vtool import numba_cache
from vtool.solvers.newmark.layout import (  # the slots and codes: see that module
    CHATTER,
    CHUNK_END,
    CI_BUILT,
    CI_HEAD,
    CI_HERTZ,
    CI_M,
    CI_NF,
    CI_ROWS,
    CI_SRC,
    CI_SRCSTEP,
    CL_AHEAD,
    CL_BEHIND,
    CL_BIT,
    CL_LAW,
    CL_MON,
    CL_PIN,
    CL_SOFT,
    CL_SRC,
    CLF_E,
    CLF_HK,
    CLF_HN,
    CLF_HV,
    CLF_SCALE,
    CM_CFF,
    CM_KFF,
    CM_MFF,
    CM_MINVFF,
    CM_SINV,
    CM_SINVF,
    CP_FINE,
    CP_RAW,
    CP_STD,
    DIVERGED,
    EV_CLOSED,
    EV_OPENED,
    EV_RELEASED,
    F_CHUNK_END,
    F_FINE_UNTIL,
    F_LAST_EVENT,
    F_T,
    FINISHED,
    FP_BETA,
    FP_DT,
    FP_FTOL,
    FP_GAMMA,
    FP_GAPNOISE,
    FP_OMEGA,
    FP_OUTDT,
    FP_REFINE,
    FP_REFWIN,
    FP_TEND,
    FP_TREV,
    FP_TTOL,
    FP_VREST,
    FP_XLIM,
    FP_ZWIN,
    I_CFG,
    I_GRID,
    I_NEED_SETTLE,
    I_NEV,
    I_NEXT_OUT,
    I_NOUT,
    I_RAPID,
    I_STARTED,
    I_STEPS,
    I_SUB,
    I_WANT_CFG,
    IP_EVERY,
    IP_N,
    IP_NCL,
    IP_NH,
    IP_NS,
    IP_ZSTICK,
    IP_ZSTOP,
    LAW_MOMENTUM,
    LAW_THESIS,
    MK_AHEAD,
    MK_BEHIND,
    MK_FORCE,
    MK_GAP,
    MK_KIND,
    MK_M,
    MK_OVERLAP,
    MK_ROW,
    NEED_CONFIG,
    OUTPUT_FULL,
    PART_C,
    PART_K,
    PART_P,
    PART_S,
    PEAK_ALL,
    PEAK_LATE,
    PEAK_OVERLAP,
    SOFT_HERTZ,
)

numba_cache.configure(os.path.dirname(os.path.abspath(__file__)))  # before numba: a read-only install caches elsewhere

from numba import njit  # noqa: E402 (after the cache folder is chosen)

from vtool import numba_link, numba_typing  # noqa: E402

numba_link.install()  # the @inner functions' libraries are link-only (see there): a quarter of the compile
numba_typing.install()  # each call's typing resolved once, not at every revisit and again in lowering (see there)

#: Module-name suffix of this source loaded a second time as plain Python (:func:`vtool.solvers.newmark.build.plain_kernel`).
PLAIN_SUFFIX = "_plain"
PLAIN = __name__.endswith(PLAIN_SUFFIX)


def _plain(function: Any) -> Any:
    return function


_OPTIONS: dict[str, Any] = {"cache": numba_cache.CACHE_ENABLED, "nogil": True, "error_model": "numpy"}
_INNER: dict[str, Any] = {**_OPTIONS, "no_cpython_wrapper": True, "no_cfunc_wrapper": True}
_NO_NRT: dict[str, Any] = {**_INNER, "_nrt": False}  # no reference counting: see "Reference counts" above
# entry points, callable from Python: the CPython wrapper only (numba's C-callable one went unused)
_ENTRY: dict[str, Any] = {**_OPTIONS, "no_cfunc_wrapper": True}
jit = _plain if PLAIN else njit(**_ENTRY)
# Called only from compiled code: no CPython or C wrapper to build (about 0.07 s of compile each).
inner = _plain if PLAIN else njit(**_NO_NRT)
# An @inner function that makes arrays (np.zeros): counted, and said so (numba would take the caller's setting).
allocating = _plain if PLAIN else njit(**_INNER, _nrt=True)
# run_chunk: an entry point without reference counting (everything it touches is its arguments' memory).
loop_entry = _plain if PLAIN else njit(**_ENTRY, _nrt=False)
# Copied into the caller as numba IR, with no compile of its own (see "Compile time" above).
tiny = _plain if PLAIN else njit(**_INNER, inline="always")

#: :func:`vtool.solvers.newmark.layout.fingerprint` of the layout this file was compiled with (see there).
LAYOUT_FINGERPRINT = "4a928e6ae8a16508"

# how a step solves S z̈ = rhs (layer_step's ``which``): stored inverses of the standard and refined
# steps, or a Cholesky factor. np.int64 values, not int literals: numba compiles a function once per
# literal argument value, and layer_step (with the Hertz iteration) is the kernel's largest callee.
STANDARD, REFINED, CHOLESKY = np.int64(0), np.int64(1), np.int64(2)

#: Quiet steps (:func:`advance`) between fresh evaluations of cos and sin of the cam angle (see there).
ANCHOR_STEPS = 64


ENTRY_POINTS = ("run_chunk", "impact", "settle", "fill_sources")  # what the back ends call from Python


def cached_signatures(name: str) -> list[tuple[Any, ...]]:
    """numba's argument types of each compiled version of function ``name`` in the cache (its index;
    empty when there is none)."""
    try:
        index = globals()[name]._cache._cache_file._load_index()
    except Exception:  # noqa: BLE001 (numba internals: no readable index)
        return []
    return [tuple(getattr(key[0], "args", key[0])) for key in index]


def is_cached(names: tuple[str, ...] = ENTRY_POINTS, hertz: bool | None = None,
              momentum: bool | None = None) -> bool:
    """True when these entry points' compiled code for these law switches (see
    :func:`~vtool.solvers.newmark.layout.laws`) is in the numba cache (no compile needed).

    Reads the cache's index (numba keeps one per function, stamped with this
    file's modification time and size, its keys led by the argument types);
    any doubt counts as not cached.
    """
    trailing = {"run_chunk": (hertz, momentum), "settle": (hertz,), "impact": (momentum,), "fill_sources": ()}
    try:
        import numba

        for name in names:
            switches = tuple(numba.typeof(value) for value in trailing[name])
            if not any(args[len(args) - len(switches):] == switches for args in cached_signatures(name)):
                return False
        return True
    except Exception:  # noqa: BLE001 (numba internals: anything unexpected means "compile")
        return False


# ----- sources -----
@inner
def sources(ns, nh, omega, sc, sa, sb, t, src):
    """src[3s : 3s + 3] = (x, v, a) of every source s at t (harmonics by angle addition)."""
    c1 = math.cos(omega * t)
    s1 = math.sin(omega * t)
    for s in range(ns):
        src[3 * s] = sc[s]
        src[3 * s + 1] = 0.0
        src[3 * s + 2] = 0.0
    ck = 1.0
    sk = 0.0
    for k in range(nh):
        ck, sk = ck * c1 - sk * s1, sk * c1 + ck * s1  # cos, sin of (k + 1) omega t
        wk = (k + 1) * omega
        for s in range(ns):
            a = sa[s, k]
            b = sb[s, k]
            src[3 * s] += a * ck + b * sk
            src[3 * s + 1] += wk * (b * ck - a * sk)
            src[3 * s + 2] -= wk * wk * (a * ck + b * sk)


@jit
def fill_sources(ns, nh, omega, sc, sa, sb, t, src):
    """:func:`sources`, for Python (the piecewise back ends; see "Compile time" above)."""
    sources(ns, nh, omega, sc, sa, sb, t, src)


# ----- layer values of a configuration -----
@inner
def gather(ci, c, n, x, v, a, z, zd, zdd):
    for j in range(ci[c, CI_M]):
        i = ci[c, CI_HEAD + j]
        z[j] = x[i]
        zd[j] = v[i]
        zdd[j] = a[i]


@inner
def scatter(ci, c, n, z, zd, zdd, x, v, a):
    for i in range(n):
        j = ci[c, CI_HEAD + n + i]
        x[i] = z[j]
        v[i] = zd[j]
        a[i] = zdd[j]


@inner
def set_prescribed(ci, c, n, src, z, zd, zdd):
    for j in range(ci[c, CI_NF], ci[c, CI_M]):
        s = ci[c, CI_HEAD + 2 * n + j]
        z[j] = src[3 * s]
        zd[j] = src[3 * s + 1]
        zdd[j] = src[3 * s + 2]


@tiny
def apply_operator(cp, c, plane, nf, nrows, m, coupled, src, z, zd, zdd, out):
    """out[:nrows] = -R·(ż_F, z_F, (z̈, ż, z)_P, src) for step operator R = cp[c, plane] (see ``CP_RAW``):
    the nf free rows, and in a step plane the force rows after them (``CI_ROWS``).

    Column by column: cp holds Rᵀ, each column's coefficients on the free rows side by side, so
    that every row's running sum takes the column's term in one pass over the rows, a loop the
    compiler runs on vectors of rows; each row is still summed in column order. Indexed in place,
    with no view of cp made per step."""
    # the rows run on to a multiple of four where out and cp have room: a whole number of 4-row vectors,
    # no row-by-row remainder; nobody reads the rows past nrows from out
    rows = min((nrows + 3) // 4 * 4, out.shape[0], cp.shape[4])
    for f in range(rows):
        out[f] = 0.0
    for g in range(nf):
        a = zd[g]
        b = z[g]
        for f in range(rows):
            out[f] -= cp[c, plane, PART_C, g, f] * a + cp[c, plane, PART_K, g, f] * b
    for p in range(m - nf):
        j = nf + p
        a = zdd[j]
        b = zd[j]
        d = z[j]
        for f in range(rows):
            out[f] -= (cp[c, plane, PART_P, 3 * p, f] * a + cp[c, plane, PART_P, 3 * p + 1, f] * b
                       + cp[c, plane, PART_P, 3 * p + 2, f] * d)
    if coupled:
        for j in range(src.shape[0]):
            a = src[j]
            for f in range(rows):
                out[f] -= cp[c, plane, PART_S, j, f] * a


@inner
def free_rhs(ci, cm, cp, c, n, src, z, zd, zdd, rhs):
    """rhs_F = -C_FF ż_F - K_FF z_F - (M_FP z̈_P + C_FP ż_P + K_FP z_P) - S_F src: the thesis' ΔP on the
    right, and the sources' pull through closed compliant contacts (``CP_RAW``)."""
    apply_operator(cp, c, CP_RAW, ci[c, CI_NF], ci[c, CI_NF], ci[c, CI_M], ci[c, CI_SRC], src, z, zd, zdd, rhs)


@inner
def factor_effective(ci, cm, c, beta, gamma, h, L):
    """Cholesky factor (lower, in place in L) of S = M_FF + gamma h C_FF + beta h² K_FF."""
    nf = ci[c, CI_NF]
    for f in range(nf):
        for g in range(f + 1):
            s = cm[c, CM_MFF, f, g] + gamma * h * cm[c, CM_CFF, f, g] + beta * h * h * cm[c, CM_KFF, f, g]
            for k in range(g):
                s -= L[f, k] * L[g, k]
            if f == g:
                L[f, f] = math.sqrt(s) if s > 0.0 else 1e-300
            else:
                L[f, g] = s / L[g, g]


@inner
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


@inner
def effective_solve(cm, c, which, L, nf, b, out):
    """out = S⁻¹ b: the stored inverse of the standard (``which`` 0) or refined (1) step, or the
    Cholesky factor in L (2)."""
    if which == 2:
        cholesky_solve(nf, L, b, out)
        return
    slot = CM_SINV if which == 0 else CM_SINVF
    for f in range(nf):
        acc = 0.0
        for g in range(nf):
            acc += cm[c, slot, f, g] * b[g]
        out[f] = acc


# ----- Hertz contacts (Hunt-Crossley) -----
@inner
def hertz_force(clf, k, delta, rate):
    """(F, dF/dδ, dF/dδ̇) of Hertz contact k: F = K δⁿ (1 + 3(1 - e)/2 · δ̇/v⁻), never pulling.

    v⁻ is the approach velocity of the contact's closing (Hunt and Crossley
    1975: the damping that gives restitution e at an impact at v⁻)."""
    if delta <= 0.0:
        return 0.0, 0.0, 0.0
    stiffness = clf[k, CLF_HK]
    exponent = clf[k, CLF_HN]
    lam = 1.5 * (1.0 - clf[k, CLF_E]) / clf[k, CLF_HV]
    power = stiffness * delta**exponent
    force = power * (1.0 + lam * rate)
    if force <= 0.0:
        return 0.0, 0.0, 0.0
    return force, exponent * power / delta * (1.0 + lam * rate), power * lam


@jit
def hertz_law(clf, k, delta, rate):
    """:func:`hertz_force`, for Python (the piecewise back ends)."""
    return hertz_force(clf, k, delta, rate)


@inner
def overlap_and_rate(mon, c, k, n, ns, z, zd, src):
    """(δ, δ̇) of a closed Hertz contact: its monitor row holds -w on z and on ż, +1 on its source."""
    delta = 0.0
    rate = 0.0
    for j in range(n):
        delta += mon[c, k, j] * z[j]
        rate += mon[c, k, n + j] * zd[j]
    for s in range(ns):
        delta += mon[c, k, 3 * n + 3 * s] * src[3 * s]
        rate += mon[c, k, 3 * n + 3 * s + 1] * src[3 * s + 1]
    return delta, rate


@inner
def compliant_force(cl, clf, mk, mon, c, k, n, ns, z, zd, zdd, src, hertz):
    """Contact force of closed compliant clearance k: the Hertz law, or its linear row."""
    if hertz is not None:
        if cl[k, CL_SOFT] == SOFT_HERTZ:
            delta, rate = overlap_and_rate(mon, c, k, n, ns, z, zd, src)
            return hertz_force(clf, k, delta, rate)[0]
    return contact_force(mk, mon, c, k, n, ns, z, zd, zdd, src)


@allocating
def hertz_correction(ci, cm, cl, clf, mk, mon, c, beta, gamma, h, which, L, n, ns, src1, z1, zd1, zdd1, sol):
    """Add the closed Hertz contacts' forces to a Newmark step whose linear part is done.

    With the linear accelerations u (in z̈1) and V_j = S⁻¹ w_j (w_j: contact
    j's direction on the free rows), z̈_F = u + Σ V_j F_j, and each overlap is
    affine in the forces: δ_k = δ_k⁰ - βh² Σ w_kᵀV_j F_j, δ̇_k = δ̇_k⁰ - γh
    Σ w_kᵀV_j F_j. Newton on F_k = H_k(δ_k(F), δ̇_k(F)) (a system of the
    closed Hertz contacts' size); then the state takes the forces.
    """
    nf = ci[c, CI_NF]
    ncl = cl.shape[0]
    idx = np.empty(ncl, dtype=np.int64)
    nc = 0
    for k in range(ncl):
        if mk[c, k, MK_KIND] == MK_OVERLAP and cl[k, CL_SOFT] == SOFT_HERTZ:
            idx[nc] = k
            nc += 1
    if nc == 0:
        return
    V = np.zeros((nf, nc))
    w = np.zeros(nf)
    col = np.zeros(nf)
    for j in range(nc):
        for f in range(nf):
            w[f] = -mon[c, idx[j], f]
        effective_solve(cm, c, which, L, nf, w, col)
        for f in range(nf):
            V[f, j] = col[f]
    A = np.zeros((nc, nc))  # δ_k per unit F_j, before the βh² and γh factors: -w_kᵀ V_j
    d0 = np.zeros(nc)
    r0 = np.zeros(nc)
    for i in range(nc):
        d0[i], r0[i] = overlap_and_rate(mon, c, idx[i], n, ns, z1, zd1, src1)
        for j in range(nc):
            acc = 0.0
            for f in range(nf):
                acc += mon[c, idx[i], f] * V[f, j]
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
            value, d_delta, d_rate = hertz_force(clf, idx[i], delta, rate)
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
        zdd1[f] += acc
        z1[f] += beta * h * h * acc
        zd1[f] += gamma * h * acc


@inner
def layer_step(ci, cm, cp, c, beta, gamma, h, which, L, n, src1, z, zd, zdd, z1, zd1, zdd1, rhs, sol,
               cl, clf, mk, mon, hertz):
    """One Newmark step of length h from layer state (z, ż, z̈) into (z1, ż1, z̈1).

    ``which``: 0 the stored S⁻¹ of the standard step, 1 of the refined step,
    2 a Cholesky factor already in ``L``. ``src1`` holds the sources at t + h.
    Closed Hertz contacts are added by Newton iteration (:func:`hertz_correction`).
    """
    m = ci[c, CI_M]
    nf = ci[c, CI_NF]
    for j in range(m):
        z1[j] = z[j] + h * zd[j] + h * h * (0.5 - beta) * zdd[j]
        zd1[j] = zd[j] + h * (1.0 - gamma) * zdd[j]
    set_prescribed(ci, c, n, src1, z1, zd1, zdd1)
    if which == CHOLESKY:
        free_rhs(ci, cm, cp, c, n, src1, z1, zd1, zdd1, rhs)
        cholesky_solve(nf, L, rhs, sol)
    else:  # z̈_F = S⁻¹ ΔP as one product with the stored G = S⁻¹R
        apply_operator(cp, c, CP_STD if which == STANDARD else CP_FINE, nf, nf, m, ci[c, CI_SRC], src1, z1, zd1,
                       zdd1, sol)
    for f in range(nf):
        zdd1[f] = sol[f]
        z1[f] += beta * h * h * sol[f]
        zd1[f] += gamma * h * sol[f]
    if hertz is not None:
        if ci[c, CI_HERTZ]:
            hertz_correction(ci, cm, cl, clf, mk, mon, c, beta, gamma, h, which, L, n, src1.shape[0] // 3, src1,
                             z1, zd1, zdd1, sol)


@inner
def consistent_acceleration(ci, cm, cp, c, n, src, z, zd, zdd, rhs, cl, clf, mk, mon, hertz):
    """Free accelerations of configuration c from its equations of motion (prescribed set from src)."""
    set_prescribed(ci, c, n, src, z, zd, zdd)
    free_rhs(ci, cm, cp, c, n, src, z, zd, zdd, rhs)
    nf = ci[c, CI_NF]
    if hertz is not None:
        if ci[c, CI_HERTZ]:  # the Hertz forces of the present overlaps, on the free rows (w = -mon row)
            for k in range(cl.shape[0]):
                if mk[c, k, MK_KIND] == MK_OVERLAP and cl[k, CL_SOFT] == SOFT_HERTZ:
                    delta, rate = overlap_and_rate(mon, c, k, n, src.shape[0] // 3, z, zd, src)
                    force = hertz_force(clf, k, delta, rate)[0]
                    for f in range(nf):
                        rhs[f] -= mon[c, k, f] * force
    for f in range(nf):
        s = 0.0
        for g in range(nf):
            s += cm[c, CM_MINVFF, f, g] * rhs[g]
        zdd[f] = s


@inner
def contact_force(mk, mon, c, k, n, ns, z, zd, zdd, src):
    """Contact force of closed clearance k: its row on (z, ż, z̈, sources, 1), summed term by term in
    the order z_0, ż_0, z̈_0, z_1, …, then the sources. (A quiet step in :func:`advance` takes the same
    force, up to round-off, from its force row in the step's product: see ``CP_RAW``.)"""
    f = mon[c, k, 3 * n + 3 * ns]
    for j in range(mk[c, k, MK_M]):
        f += mon[c, k, j] * z[j]
        f += mon[c, k, n + j] * zd[j]
        f += mon[c, k, 2 * n + j] * zdd[j]
    for j in range(3 * ns):
        f += mon[c, k, 3 * n + j] * src[j]
    return f


@inner
def rigid_force(cl, clf, mk, mon, c, k, n, ns, z, zd, zdd, src, hertz):
    """Contact force of closed rigid clearance k: its linear row, plus the closed Hertz contacts' pull
    on it (``mon[c, k, 3n + 3ns + 1 + j]`` per unit Hertz force F_j)."""
    f = contact_force(mk, mon, c, k, n, ns, z, zd, zdd, src)
    if hertz is not None:
        head = 3 * n + 3 * ns + 1
        for j in range(cl.shape[0]):
            if mon[c, k, head + j] != 0.0:
                delta, rate = overlap_and_rate(mon, c, j, n, ns, z, zd, src)
                f += mon[c, k, head + j] * hertz_force(clf, j, delta, rate)[0]
    return f


@inner
def monitor_value(cl, clf, mk, mon, c, k, n, ns, gap_noise, z, zd, zdd, src, hertz):
    """What changes sign at clearance k's next event; 0 when not monitored.

    Open: gap + allowance. Closed rigid: the contact force. Closed compliant:
    the overlap δ = -gap + allowance (the contact ends when the parts part).
    """
    kind = mk[c, k, MK_KIND]
    if kind == MK_GAP or kind == MK_OVERLAP:
        behind = mk[c, k, MK_BEHIND]
        other = z[behind] if behind >= 0 else src[3 * (-1 - behind)]
        gap = z[mk[c, k, MK_AHEAD]] - other
        return (gap if kind == MK_GAP else -gap) + gap_noise
    if kind == MK_FORCE:
        if hertz is None:  # the linear row alone, inline (no call)
            return contact_force(mk, mon, c, k, n, ns, z, zd, zdd, src)
        return rigid_force(cl, clf, mk, mon, c, k, n, ns, z, zd, zdd, src, hertz)
    return 0.0


@inner
def monitors(cl, clf, mk, mon, c, n, ns, ncl, gap_noise, z, zd, zdd, src, phi, hertz):
    """phi[k] = :func:`monitor_value` of every clearance k: one call for all of them."""
    for k in range(ncl):
        phi[k] = monitor_value(cl, clf, mk, mon, c, k, n, ns, gap_noise, z, zd, zdd, src, hertz)


# ----- output -----
@inner
def record_row(ci, cl, clf, mk, mon, c, n, ns, ncl, gap_noise, t, z, zd, zdd, src, out_t, out_q, out_F, out_c,
               row, hertz):
    out_t[row] = t
    out_c[row] = c
    for i in range(n):
        j = ci[c, CI_HEAD + n + i]
        out_q[0, row, i] = z[j]
        out_q[1, row, i] = zd[j]
        out_q[2, row, i] = zdd[j]
    for s in range(ns):
        out_q[0, row, n + s] = src[3 * s]
        out_q[1, row, n + s] = src[3 * s + 1]
        out_q[2, row, n + s] = src[3 * s + 2]
    for k in range(ncl):
        if mk[c, k, MK_KIND] == MK_FORCE:
            out_F[row, k] = rigid_force(cl, clf, mk, mon, c, k, n, ns, z, zd, zdd, src, hertz)
        elif mk[c, k, MK_KIND] == MK_OVERLAP:
            out_F[row, k] = compliant_force(cl, clf, mk, mon, c, k, n, ns, z, zd, zdd, src, hertz)
        else:
            out_F[row, k] = 0.0


# ----- impacts -----
@inner
def add_event(ev_f, ev_i, ist, t, k, kind, u, c_from, c_to):
    row = ist[I_NEV]
    if row < ev_f.shape[0]:
        ev_f[row, 0] = t
        ev_f[row, 1] = u
        ev_i[row, 0] = k
        ev_i[row, 1] = kind
        ev_i[row, 2] = c_from
        ev_i[row, 3] = c_to
    ist[I_NEV] = row + 1


@inner
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


@allocating
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


@allocating
def impact_momentum(ip, fp, cl, clf, mass, c, closing, src, x, v, stick, ev_f, ev_i, ist, t):
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
    n = ip[IP_N]
    ncl = ip[IP_NCL]
    idx = np.empty(ncl, dtype=np.int64)
    nc = 0
    for k in range(ncl):
        if ((c & cl[k, CL_BIT]) and not cl[k, CL_SOFT]) or closing[k]:
            idx[nc] = k
            nc += 1
    G = np.zeros((nc, n))
    u = np.zeros(nc)
    b = np.zeros(nc)
    eq = np.zeros(nc, dtype=np.int64)
    for r in range(nc):
        k = idx[r]
        G[r, cl[k, CL_AHEAD]] = 1.0
        wsrc = 0.0
        if cl[k, CL_BEHIND] >= 0:
            G[r, cl[k, CL_BEHIND]] -= 1.0
        else:
            wsrc = src[3 * cl[k, CL_SRC] + 1]
        for i in range(n):
            u[r] += G[r, i] * v[i]
        u[r] -= wsrc
        if closing[k]:
            e = 0.0 if (stick or abs(u[r]) < fp[FP_VREST]) else clf[k, CLF_E]
            b[r] = -e * u[r]
        eq[r] = cl[k, CL_PIN] or stick
    MG = np.zeros((n, nc))  # M⁻¹ Gᵀ
    for i in range(n):
        for r in range(nc):
            s = 0.0
            for j in range(n):
                s += mass[1, i, j] * G[r, j]
            MG[i, r] = s
    W = np.zeros((nc, nc))
    for r in range(nc):
        for q in range(nc):
            s = 0.0
            for i in range(n):
                s += G[r, i] * MG[i, q]
            W[r, q] = s
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
            if not eq[r] and 10.0 * scale < uplus[r] < fp[FP_VREST]:
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
            mask |= cl[k, CL_BIT]
        else:
            mask &= ~cl[k, CL_BIT]
    for r in range(nc):
        k = idx[r]
        if closing[k]:
            add_event(ev_f, ev_i, ist, t, k, EV_CLOSED, u[r], c, mask)
        elif not (mask & cl[k, CL_BIT]):
            add_event(ev_f, ev_i, ist, t, k, EV_RELEASED, uplus[r], c, mask)
    return mask


@inner
def prescribed_velocity(cl, c, ncl, coordinate, src):
    """Velocity of the source a coordinate is tied to in configuration c, or nan if it is free."""
    for k in range(ncl):
        if (c & cl[k, CL_BIT]) and not cl[k, CL_SOFT] and cl[k, CL_BEHIND] < 0 and cl[k, CL_AHEAD] == coordinate:
            return src[3 * cl[k, CL_SRC] + 1]
    return math.nan


@inner
def impact_local(ip, fp, cl, clf, mass, c, k, src, v, stick, ev_f, ev_i, ist, t):
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
    ncl = ip[IP_NCL]
    a = cl[k, CL_AHEAD]
    behind = cl[k, CL_BEHIND]
    if behind < 0:
        w = src[3 * cl[k, CL_SRC] + 1]
        u = v[a] - w
        e = 0.0 if (stick or abs(u) < fp[FP_VREST]) else clf[k, CLF_E]
        v[a] = w - e * u
    else:
        u = v[a] - v[behind]
        e = 0.0 if (stick or abs(u) < fp[FP_VREST]) else clf[k, CLF_E]
        wa = prescribed_velocity(cl, c, ncl, a, src)
        wb = prescribed_velocity(cl, c, ncl, behind, src)
        if not math.isnan(wa):  # a follows a source: b alone changes
            v[behind] = wa + e * u
        elif not math.isnan(wb):
            v[a] = wb - e * u
        else:
            ma = mass[0, a, a]
            mb = mass[0, behind, behind]
            if cl[k, CL_LAW] == LAW_THESIS:
                common = clf[k, CLF_SCALE] * v[a]
            else:
                common = (ma * v[a] + mb * v[behind]) / (ma + mb)
            uplus = -e * u
            v[a] = common + mb / (ma + mb) * uplus
            v[behind] = common - ma / (ma + mb) * uplus
    mask = c
    if e * abs(u) <= 0.0:
        mask |= cl[k, CL_BIT]
    add_event(ev_f, ev_i, ist, t, k, EV_CLOSED, u, c, mask)
    return mask


@inner
def shut_gap(cl, k, x, src):
    """Clearance k's gap (or overlap) set to exactly zero: it is within the time tolerance of zero."""
    x[cl[k, CL_AHEAD]] = x[cl[k, CL_BEHIND]] if cl[k, CL_BEHIND] >= 0 else src[3 * cl[k, CL_SRC]]


@jit
def snap_shut(cl, k, x, src):
    """:func:`shut_gap`, for Python (the piecewise back ends)."""
    shut_gap(cl, k, x, src)


@inner
def gap_velocity(cl, k, v, src):
    """Velocity of clearance k's gap: v_ahead - v_behind (or the source's)."""
    behind = cl[k, CL_BEHIND]
    return v[cl[k, CL_AHEAD]] - (v[behind] if behind >= 0 else src[3 * cl[k, CL_SRC] + 1])


@jit
def relative_velocity(cl, k, v, src):
    """:func:`gap_velocity`, for Python (the piecewise back ends)."""
    return gap_velocity(cl, k, v, src)


@allocating
def apply_impacts(ip, fp, cl, clf, mass, c, closing, src, x, v, stick, ev_f, ev_i, ist, t, momentum):
    """Apply the impact law of every closing clearance at t; returns the new configuration mask.

    Local-law closings are applied one after the other (each changes only its
    own coordinates); momentum-law closings are solved together with every
    closed contact (:func:`impact_momentum`). Gaps are snapped shut (they are
    within the time tolerance). A compliant clearance closes with no jump: its
    spring and dashpot take over (the event records its approach velocity).
    """
    ncl = ip[IP_NCL]
    mask = c
    any_momentum = False
    for k in range(ncl):
        if not closing[k]:
            continue
        shut_gap(cl, k, x, src)
        if cl[k, CL_SOFT]:
            mask |= cl[k, CL_BIT]
            u = gap_velocity(cl, k, v, src)
            clf[k, CLF_HV] = max(-u, fp[FP_VREST], 1e-300)  # the Hertz contact's approach velocity
            add_event(ev_f, ev_i, ist, t, k, EV_CLOSED, u, c, mask)
        elif cl[k, CL_LAW] == LAW_MOMENTUM:
            any_momentum = True
        else:
            mask = impact_local(ip, fp, cl, clf, mass, mask, k, src, v, stick, ev_f, ev_i, ist, t)
    if momentum is not None:  # None: no clearance has the momentum law (see laws), and no array is made
        if any_momentum:
            joint = np.zeros(ncl, dtype=np.int64)  # the momentum-law closings, solved together
            for k in range(ncl):
                if closing[k] and not cl[k, CL_SOFT] and cl[k, CL_LAW] == LAW_MOMENTUM:
                    joint[k] = 1
            mask = impact_momentum(ip, fp, cl, clf, mass, mask, joint, src, x, v, stick, ev_f, ev_i, ist, t)
    return mask


@jit
def impact(ip, fp, cl, clf, mass, c, closing, src, x, v, stick, ev_f, ev_i, ist, t, momentum):
    """:func:`apply_impacts`, for Python (the piecewise back ends)."""
    return apply_impacts(ip, fp, cl, clf, mass, c, closing, src, x, v, stick, ev_f, ev_i, ist, t, momentum)


@inner
def release_pulling(ip, fp, cl, clf, ci, cm, cp, mk, mon, c, t, x, v, a, src, ev_f, ev_i, ist, rhs, z, zd, zdd, hertz):
    """Consistent accelerations of configuration c; release at once every contact that would pull.

    Returns the settled configuration, or -1 - c2 when configuration c2 must
    be built first (call again after building it). The most pulling contact
    is released first and the accelerations recomputed, until every closed
    contact pushes (at most one release per clearance).
    """
    n = ip[IP_N]
    ns = ip[IP_NS]
    ncl = ip[IP_NCL]
    for _ in range(ncl + 1):
        if not ci[c, CI_BUILT]:
            return -1 - c
        gather(ci, c, n, x, v, a, z, zd, zdd)
        consistent_acceleration(ci, cm, cp, c, n, src, z, zd, zdd, rhs, cl, clf, mk, mon, hertz)
        scatter(ci, c, n, z, zd, zdd, x, v, a)
        worst = -1
        worst_f = -fp[FP_FTOL]
        for k in range(ncl):
            if mk[c, k, MK_KIND] == MK_FORCE and cl[k, CL_MON]:
                f = rigid_force(cl, clf, mk, mon, c, k, n, ns, z, zd, zdd, src, hertz)
                if f < worst_f:
                    worst = k
                    worst_f = f
        if worst < 0:
            return c
        new_c = c & ~cl[worst, CL_BIT]
        add_event(ev_f, ev_i, ist, t, worst, EV_OPENED, 0.0, c, new_c)
        c = new_c
    return c


@jit
def settle(ip, fp, cl, clf, ci, cm, cp, mk, mon, c, t, x, v, a, src, ev_f, ev_i, ist, rhs, z, zd, zdd, hertz):
    """:func:`release_pulling`, for Python (the piecewise back ends)."""
    return release_pulling(ip, fp, cl, clf, ci, cm, cp, mk, mon, c, t, x, v, a, src, ev_f, ev_i, ist, rhs, z, zd, zdd,
                           hertz)


# ----- event location -----
@inner
def locate_event(ci, cm, cp, cl, clf, mk, mon, c, k, n, ns, nh, fp, sc, sa, sb, t, h, phi_lo, phi_hi,
                 z, zd, zdd, z1, zd1, zdd1, src1, rhs, sol, L, hertz):
    """Earliest tau in (0, h] where monitor k crosses zero, re-stepping from (z, ż, z̈) at t.

    Illinois (modified regula falsi) on phi(tau) = monitor after a Newmark
    step of length tau, bracketed by phi(0) >= 0 > phi(h), with a bisection
    whenever two iterations have not halved the bracket; returns the left end
    of the final bracket (the monitor still non-negative), within the time
    tolerance of the crossing. Each trial factors S(tau) by Cholesky.
    """
    beta, gamma, tol = fp[FP_BETA], fp[FP_GAMMA], fp[FP_TTOL]
    lo, hi = 0.0, h
    flo, fhi = phi_lo, phi_hi
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
        sources(ns, nh, fp[FP_OMEGA], sc, sa, sb, t + tau, src1)
        factor_effective(ci, cm, c, beta, gamma, tau, L)
        layer_step(ci, cm, cp, c, beta, gamma, tau, CHOLESKY, L, n, src1, z, zd, zdd, z1, zd1, zdd1, rhs, sol,
                   cl, clf, mk, mon, hertz)
        f = monitor_value(cl, clf, mk, mon, c, k, n, ns, fp[FP_GAPNOISE], z1, zd1, zdd1, src1, hertz)
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


@inner
def track_peaks(cl, clf, mk, mon, c, n, ns, ncl, gap_noise, after, phi, z, zd, zdd, src, peak, hertz):
    """Raise the peak contact forces (and compliant overlaps) with the monitors ``phi`` at a step's end."""
    for k in range(ncl):
        kind = mk[c, k, MK_KIND]
        force = phi[k]
        if kind == MK_OVERLAP:
            force = compliant_force(cl, clf, mk, mon, c, k, n, ns, z, zd, zdd, src, hertz)
            peak[PEAK_OVERLAP, k] = max(peak[PEAK_OVERLAP, k], phi[k] - gap_noise)
        elif kind != MK_FORCE:
            continue
        peak[PEAK_ALL, k] = max(peak[PEAK_ALL, k], force)
        if after:
            peak[PEAK_LATE, k] = max(peak[PEAK_LATE, k], force)


# ----- the hot loop -----
@inner
def advance(ip, fp, cl, sc, sa, sb, ci, cm, cp, mk, mon, out_t, out_q, out_F, out_c, peak, ist, fst, c,
            z, zd, zdd, z1, zd1, zdd1, src1, srco, zo, zdo, zddo, rhs, phi):
    """Standard and refined steps in configuration c while nothing happens; returns the time reached.

    Everything a quiet step does is written out here, in one loop with no
    call per step to another compiled function: the Newmark step
    with the stored effective inverse, the sources (the cam angle's cos and
    sin by rotation, see ``ANCHOR_STEPS``), the monitors, the output rows at
    the output instants, the peaks. It stops, without taking it, at
    the first step that is neither a standard step on the grid nor a refined
    one, that would end past the chunk or the run, change a monitor's sign,
    leave the divergence limit or overflow the output buffer;
    :func:`run_chunk` takes that step with full handling. Not called in
    every-step mode, nor in a configuration with closed Hertz contacts (each
    of their steps goes through layer_step's iteration).
    """
    n, ncl, ns, nh = ip[IP_N], ip[IP_NCL], ip[IP_NS], ip[IP_NH]
    beta, gamma, dt, t_end, out_dt = fp[FP_BETA], fp[FP_GAMMA], fp[FP_DT], fp[FP_TEND], fp[FP_OUTDT]
    omega, gap_noise, x_limit, t_rev = fp[FP_OMEGA], fp[FP_GAPNOISE], fp[FP_XLIM], fp[FP_TREV]
    refine = int(fp[FP_REFINE] + 0.5)
    fine = dt / refine
    m = ci[c, CI_M]
    nf = ci[c, CI_NF]
    nrows = ci[c, CI_ROWS]
    coupled = ci[c, CI_SRCSTEP]
    rows = out_t.shape[0]
    # this configuration's monitor tables, taken once (inner loops then index two dimensions, not three)
    W = mon[c]
    kinds = mk[c]
    t = fst[F_T]
    # cos, sin of omega t, carried from step to step by the rotation through one step's angle (libm's
    # sincos took a seventh of a quiet step: 172 against 148 ns/step on 1A, bench_step_ab.py), and taken
    # afresh every ANCHOR_STEPS steps: the rotation's round-off grows by an ulp or two a step, so they
    # stay within about 1e-13 of libm's, the round-off of the angle omega t itself at a few hundred rad
    c0 = math.cos(omega * t)
    s0 = math.sin(omega * t)
    c_dt = math.cos(omega * dt)
    s_dt = math.sin(omega * dt)
    c_fine = math.cos(omega * fine)
    s_fine = math.sin(omega * fine)
    rotated = 0
    # the state at t and the step's end: the caller's (z, ż, z̈) and (z1, ż1, z̈1), which change places at
    # each step taken (no copy); on return the state is in the caller's (z, ż, z̈)
    za, zda, zdda = z, zd, zdd
    zb, zdb, zddb = z1, zd1, zdd1
    swapped = False
    while True:
        k_grid = ist[I_GRID]
        sub = ist[I_SUB]
        if sub > 0 or t < fst[F_FINE_UNTIL]:  # refined steps on their grid, on to the next grid point
            if t != k_grid * dt + sub * fine:
                break
            h = fine
            plane = CP_FINE
            t1 = (k_grid + 1) * dt if sub + 1 == refine else k_grid * dt + (sub + 1) * fine
        elif t == k_grid * dt:
            h = dt
            plane = CP_STD
            t1 = (k_grid + 1) * dt
        else:
            break
        if t1 > t_end or t >= fst[F_CHUNK_END]:
            break
        # the sources at t + h (sources' arithmetic, written out: the quiet step's loop bounds stay local)
        if rotated == ANCHOR_STEPS:
            c1 = math.cos(omega * t1)
            s1 = math.sin(omega * t1)
        elif plane == CP_STD:
            c1 = c0 * c_dt - s0 * s_dt
            s1 = s0 * c_dt + c0 * s_dt
        else:
            c1 = c0 * c_fine - s0 * s_fine
            s1 = s0 * c_fine + c0 * s_fine
        for s in range(ns):
            src1[3 * s] = sc[s]
            src1[3 * s + 1] = 0.0
            src1[3 * s + 2] = 0.0
        ck = 1.0
        sk = 0.0
        for kh in range(nh):
            ck, sk = ck * c1 - sk * s1, sk * c1 + ck * s1
            wk = (kh + 1) * omega
            for s in range(ns):
                ca = sa[s, kh]
                cb = sb[s, kh]
                src1[3 * s] += ca * ck + cb * sk
                src1[3 * s + 1] += wk * (cb * ck - ca * sk)
                src1[3 * s + 2] -= wk * wk * (ca * ck + cb * sk)
        # the Newmark step (see layer_step)
        hx = h * h * (0.5 - beta)
        hv = h * (1.0 - gamma)
        bx = beta * h * h
        gv = gamma * h
        for j in range(m):
            zb[j] = za[j] + h * zda[j] + hx * zdda[j]
            zdb[j] = zda[j] + hv * zdda[j]
        for j in range(nf, m):
            sidx = ci[c, CI_HEAD + 2 * n + j]
            zb[j] = src1[3 * sidx]
            zdb[j] = src1[3 * sidx + 1]
            zddb[j] = src1[3 * sidx + 2]
        apply_operator(cp, c, plane, nf, nrows, m, coupled, src1, zb, zdb, zddb, rhs)
        stop = False
        for f in range(nf):
            acc = rhs[f]
            zddb[f] = acc
            zb[f] += bx * acc
            zdb[f] += gv * acc
            if not (abs(zb[f]) <= x_limit):  # the divergence limit
                stop = True
        if stop:
            break
        # monitors (see monitor_value): stop before a sign change
        for k in range(ncl):
            kind = kinds[k, MK_KIND]
            value = 0.0
            if kind == MK_GAP or kind == MK_OVERLAP:
                behind = kinds[k, MK_BEHIND]
                other = zb[behind] if behind >= 0 else src1[3 * (-1 - behind)]
                value = zb[kinds[k, MK_AHEAD]] - other
                value = (value if kind == MK_GAP else -value) + gap_noise
                if value < 0.0:
                    stop = True
                    break
            elif kind == MK_FORCE:  # its force row of the step's product, and the row's constant
                value = W[k, 3 * n + 3 * ns] + rhs[kinds[k, MK_ROW]]
                if value < 0.0 and cl[k, CL_MON]:
                    stop = True
                    break
            phi[k] = value
        if stop:
            break
        # output rows inside (t, t + h] (see run_chunk)
        while True:
            j_out = ist[I_NEXT_OUT]
            t_out = j_out * out_dt
            if t_out > t1 + 1e-9 * dt or t_out > t_end + 1e-9 * dt:
                break
            row = ist[I_NOUT]
            if row >= rows:
                stop = True
                break
            interpolate(nf, t_out - t, h, za, zda, zdda, zddb, zo, zdo, zddo)
            sources(ns, nh, omega, sc, sa, sb, t_out, srco)
            set_prescribed(ci, c, n, srco, zo, zdo, zddo)
            out_t[row] = t_out
            out_c[row] = c
            for i in range(n):
                j = ci[c, CI_HEAD + n + i]
                out_q[0, row, i] = zo[j]
                out_q[1, row, i] = zdo[j]
                out_q[2, row, i] = zddo[j]
            for s in range(ns):
                out_q[0, row, n + s] = srco[3 * s]
                out_q[1, row, n + s] = srco[3 * s + 1]
                out_q[2, row, n + s] = srco[3 * s + 2]
            for k in range(ncl):
                force = 0.0
                if mk[c, k, MK_KIND] == MK_FORCE or mk[c, k, MK_KIND] == MK_OVERLAP:
                    force = contact_force(mk, mon, c, k, n, ns, zo, zdo, zddo, srco)
                out_F[row, k] = force
            ist[I_NOUT] = row + 1
            ist[I_NEXT_OUT] = j_out + 1
        if stop:
            break
        # accept: peaks, state, time
        after = t1 >= t_rev
        for k in range(ncl):
            kind = kinds[k, MK_KIND]
            if kind == MK_FORCE:
                if phi[k] > peak[PEAK_ALL, k]:
                    peak[PEAK_ALL, k] = phi[k]
                if after and phi[k] > peak[PEAK_LATE, k]:
                    peak[PEAK_LATE, k] = phi[k]
            elif kind == MK_OVERLAP:
                force = contact_force(mk, mon, c, k, n, ns, zb, zdb, zddb, src1)
                if force > peak[PEAK_ALL, k]:
                    peak[PEAK_ALL, k] = force
                if after and force > peak[PEAK_LATE, k]:
                    peak[PEAK_LATE, k] = force
                if phi[k] - gap_noise > peak[PEAK_OVERLAP, k]:
                    peak[PEAK_OVERLAP, k] = phi[k] - gap_noise
        za, zb = zb, za  # the step's end is the state: the two buffers change places
        zda, zdb = zdb, zda
        zdda, zddb = zddb, zdda
        swapped = not swapped
        ist[I_STEPS] += 1
        if plane == CP_STD or sub + 1 == refine:
            ist[I_GRID] = k_grid + 1
            ist[I_SUB] = 0
        else:
            ist[I_SUB] = sub + 1
        t = t1
        fst[F_T] = t
        c0 = c1
        s0 = s1
        rotated = 0 if rotated == ANCHOR_STEPS else rotated + 1
    if swapped:  # the state is in the caller's step-end buffers: back into its state buffers
        for j in range(m):
            z[j] = za[j]
            zd[j] = zda[j]
            zdd[j] = zdda[j]
    return t


@inner
def interpolate(nf, s_out, h, z, zd, zdd, zdd1, zo, zdo, zddo):
    """The free coordinates at s_out into a step of length h from (z, ż, z̈) whose end acceleration is
    z̈1: the linear-acceleration interpolant (exact for beta = 1/6; thesis eqs. B.3-B.5)."""
    r = s_out / h
    for j in range(nf):
        da = zdd1[j] - zdd[j]
        zddo[j] = zdd[j] + da * r
        zdo[j] = zd[j] + zdd[j] * s_out + da * s_out * r / 2.0
        zo[j] = z[j] + zd[j] * s_out + zdd[j] * s_out * s_out / 2.0 + da * s_out * s_out * r / 6.0


@inner
def step_rows(ci, cl, clf, mk, mon, c, n, ns, nh, ncl, fp, sc, sa, sb, t, h, z, zd, zdd, z1, zd1, zdd1, zo, zdo, zddo,
              srco, out_t, out_q, out_F, out_c, ist, hertz):
    """The output rows inside (t, t + h] of a step from (z, ż, z̈) to (z1, ż1, z̈1) taken by
    :func:`run_chunk` (see there); False when the buffer filled first."""
    dt, t_end, out_dt, omega, gap_noise = fp[FP_DT], fp[FP_TEND], fp[FP_OUTDT], fp[FP_OMEGA], fp[FP_GAPNOISE]
    rows = out_t.shape[0]
    while True:
        j_out = ist[I_NEXT_OUT]
        t_out = j_out * out_dt
        if t_out > t + h + 1e-9 * dt or t_out > t_end + 1e-9 * dt:
            return True
        if ist[I_NOUT] >= rows:
            return False
        interpolate(ci[c, CI_NF], t_out - t, h, z, zd, zdd, zdd1, zo, zdo, zddo)
        sources(ns, nh, omega, sc, sa, sb, t_out, srco)
        set_prescribed(ci, c, n, srco, zo, zdo, zddo)
        record_row(ci, cl, clf, mk, mon, c, n, ns, ncl, gap_noise, t_out, zo, zdo, zddo, srco,
                   out_t, out_q, out_F, out_c, ist[I_NOUT], hertz)
        ist[I_NOUT] += 1
        ist[I_NEXT_OUT] = j_out + 1


@inner
def take_events(ip, fp, cl, clf, mass, c, t, h, tau, closing, x, v, src0, ev_f, ev_i, ist, fst, momentum):
    """The events at t of configuration c: each monitor k that crossed within the time tolerance of
    the located step h (``tau[k] <= h + tol``) opens its contact, or closes it by an impact. Returns
    the configuration after them, or -1 when the contacts chatter (``IP_ZSTOP`` rapid events)."""
    ncl = ip[IP_NCL]
    tol = fp[FP_TTOL]
    new_c = c
    any_closing = False
    for k in range(ncl):
        closing[k] = 0
        if cl[k, CL_MON] and tau[k] <= h + tol:
            if c & cl[k, CL_BIT]:
                new_c &= ~cl[k, CL_BIT]
            else:
                closing[k] = 1
                any_closing = True
    rapid = t - fst[F_LAST_EVENT] <= fp[FP_ZWIN]
    ist[I_RAPID] = ist[I_RAPID] + 1 if rapid else 0
    fst[F_LAST_EVENT] = t
    if ist[I_RAPID] >= ip[IP_ZSTOP]:
        return -1
    stick = ist[I_RAPID] >= ip[IP_ZSTICK]
    for k in range(ncl):
        if (c & cl[k, CL_BIT]) and not (new_c & cl[k, CL_BIT]):
            u = 0.0
            if cl[k, CL_SOFT]:  # the parts leave with their relative velocity; the overlap is shut
                shut_gap(cl, k, x, src0)
                u = gap_velocity(cl, k, v, src0)
            add_event(ev_f, ev_i, ist, t, k, EV_OPENED, u, c, new_c)
    if any_closing:
        new_c = apply_impacts(ip, fp, cl, clf, mass, new_c, closing, src0, x, v, stick, ev_f, ev_i, ist, t,
                              momentum)
    return new_c


@inner
def copy_state(m, z, zd, zdd, src, z_to, zd_to, zdd_to, src_to):
    """The first m entries of (z, ż, z̈), and the sources, into (z_to, ż_to, z̈_to) and src_to."""
    for j in range(m):
        z_to[j] = z[j]
        zd_to[j] = zd[j]
        zdd_to[j] = zdd[j]
    for j in range(src.shape[0]):
        src_to[j] = src[j]


@inner
def arrive(ist, fst, target, grid_next, k_grid, j_target):
    """Now at ``target``: the next standard grid point, or point ``j_target`` of the refined grid."""
    if target == grid_next:
        ist[I_GRID] = k_grid + 1
        ist[I_SUB] = 0
    else:
        ist[I_SUB] = j_target
    fst[F_T] = target
    return target


# ----- the run loop -----
@loop_entry
def run_chunk(ip, fp, cl, clf, sc, sa, sb, mass, ci, cm, cp, mk, mon,
              out_t, out_q, out_F, out_c, ev_f, ev_i, peak, x, v, a, ist, fst, work, L, closing, hertz, momentum):
    """Integrate from fst[F_T] until t_end, the chunk end, or something Python must do.

    Returns a status (FINISHED, CHUNK_END, NEED_CONFIG, OUTPUT_FULL, DIVERGED,
    CHATTER). (x, v, a) is the full state at fst[F_T] in configuration
    ist[I_CFG]; everything needed to resume is in the arguments, so Python may
    build a configuration or empty a buffer and call again. Output rows at the
    output instants are interpolated inside the step by the linear-acceleration
    interpolant (exact for beta = 1/6; thesis eqs. B.3–B.5); ``peak[PEAK_ALL]``
    holds the peak contact forces over every step, ``peak[PEAK_LATE]`` those
    after the first cam revolution, ``peak[PEAK_OVERLAP]`` the largest overlap
    of each compliant contact. ``work`` (kernel_layout.WORK_PER_N n +
    WORK_PER_SOURCE ns + WORK_PER_CLEARANCE ncl values), ``L`` (n x n) and ``closing`` (ncl) are
    scratch, zeroed here at each call as fresh arrays would be: the steps
    allocate none (numba's ``np.zeros`` costs each compiling process about a
    second of compile the first time). Only the momentum law's impacts and
    the Hertz iteration allocate their small systems (at such an impact, or a
    step with a closed Hertz contact), in the kernels compiled with them
    (``kernel_layout.laws``).
    """
    n, ncl, ns, nh = ip[IP_N], ip[IP_NCL], ip[IP_NS], ip[IP_NH]
    every = ip[IP_EVERY]
    beta, gamma, dt, t_end, out_dt = fp[FP_BETA], fp[FP_GAMMA], fp[FP_DT], fp[FP_TEND], fp[FP_OUTDT]
    omega, gap_noise, x_limit = fp[FP_OMEGA], fp[FP_GAPNOISE], fp[FP_XLIM]
    refine = int(fp[FP_REFINE] + 0.5)
    fine = dt / refine
    t_rev = fp[FP_TREV]
    for i in range(work.shape[0]):
        work[i] = 0.0
    for i in range(n):
        for j in range(n):
            L[i, j] = 0.0
    for k in range(ncl):
        closing[k] = 0
    z = work[:n]
    zd = work[n:2 * n]
    zdd = work[2 * n:3 * n]
    z1 = work[3 * n:4 * n]  # a step's end
    zd1 = work[4 * n:5 * n]
    zdd1 = work[5 * n:6 * n]
    src1 = work[6 * n:6 * n + 3 * ns]
    o = 6 * n + 3 * ns
    zo = work[o:o + n]
    zdo = work[o + n:o + 2 * n]
    zddo = work[o + 2 * n:o + 3 * n]
    rhs = work[o + 3 * n:o + 4 * n + ncl]  # the free rows, then the force rows of a quiet step's product
    sol = work[o + 4 * n + ncl:o + 5 * n + ncl]
    o += 5 * n + ncl
    src0 = work[o:o + 3 * ns]
    srco = work[o + 3 * ns:o + 6 * ns]
    o += 6 * ns
    phi = work[o:o + ncl]
    phi_start = work[o + ncl:o + 2 * ncl]
    tau = work[o + 2 * ncl:o + 3 * ncl]
    rows = out_t.shape[0]
    while True:
        t = fst[F_T]
        c = ist[I_CFG]
        if not ci[c, CI_BUILT]:
            ist[I_WANT_CFG] = c
            return NEED_CONFIG
        if ist[I_NEV] + 3 * ncl + 2 >= ev_f.shape[0]:
            return OUTPUT_FULL
        sources(ns, nh, omega, sc, sa, sb, t, src0)
        if ist[I_NEED_SETTLE]:
            settled = release_pulling(ip, fp, cl, clf, ci, cm, cp, mk, mon, c, t, x, v, a, src0, ev_f, ev_i, ist,
                                      rhs, z, zd, zdd, hertz)
            if settled < 0:
                ist[I_CFG] = -1 - settled
                ist[I_WANT_CFG] = -1 - settled
                return NEED_CONFIG
            c = settled
            ist[I_CFG] = c
            ist[I_NEED_SETTLE] = 0
            if not ist[I_STARTED]:  # the start is an output row and counts for the peaks
                if ist[I_NOUT] >= rows:
                    return OUTPUT_FULL
                gather(ci, c, n, x, v, a, z, zd, zdd)
                record_row(ci, cl, clf, mk, mon, c, n, ns, ncl, gap_noise, t, z, zd, zdd, src0,
                           out_t, out_q, out_F, out_c, ist[I_NOUT], hertz)
                for k in range(ncl):
                    peak[PEAK_ALL, k] = max(peak[PEAK_ALL, k], out_F[ist[I_NOUT], k])
                ist[I_NOUT] += 1
                ist[I_NEXT_OUT] = 1
                ist[I_STARTED] = 1
        gather(ci, c, n, x, v, a, z, zd, zdd)
        # ---- steps in configuration c until an event, the chunk end or a full buffer ----
        status = 0
        event = False
        while True:
            if t >= t_end - 1e-9 * dt:
                status = FINISHED
                break
            if t >= fst[F_CHUNK_END]:
                status = CHUNK_END
                break
            k_grid = ist[I_GRID]
            sub = ist[I_SUB]
            refined = sub > 0 or t < fst[F_FINE_UNTIL]
            # on a point of the step grid (advance's own test): quiet steps may follow. Off it, after an
            # event, the call would return at once
            if t == (k_grid * dt + sub * fine if refined else k_grid * dt) and not (every or ci[c, CI_HERTZ]):
                t_quiet = advance(ip, fp, cl, sc, sa, sb, ci, cm, cp, mk, mon, out_t, out_q, out_F, out_c, peak,
                                  ist, fst, c, z, zd, zdd, z1, zd1, zdd1, src1, srco, zo, zdo, zddo, rhs, phi)
                if t_quiet != t:  # quiet steps taken: sources at the new time, then the end checks again
                    t = t_quiet
                    sources(ns, nh, omega, sc, sa, sb, t, src0)
                    continue
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
            if h <= 1e-9 * dt:  # at a grid point but for round-off
                t = arrive(ist, fst, target, grid_next, k_grid, j_target)
                continue
            sources(ns, nh, omega, sc, sa, sb, t + h, src1)
            which = STANDARD
            if h != dt:
                if h == fine:
                    which = REFINED
                else:
                    which = CHOLESKY
                    factor_effective(ci, cm, c, beta, gamma, h, L)
            layer_step(ci, cm, cp, c, beta, gamma, h, which, L, n, src1, z, zd, zdd, z1, zd1, zdd1, rhs, sol,
                       cl, clf, mk, mon, hertz)
            monitors(cl, clf, mk, mon, c, n, ns, ncl, gap_noise, z1, zd1, zdd1, src1, phi, hertz)
            fired = False
            for k in range(ncl):
                if cl[k, CL_MON] and phi[k] < 0.0:
                    fired = True
            if fired:  # locate every sign change; the earliest is taken
                monitors(cl, clf, mk, mon, c, n, ns, ncl, gap_noise, z, zd, zdd, src0, phi_start, hertz)
                tau_min = 2.0 * h
                for k in range(ncl):
                    tau[k] = 2.0 * h
                    if cl[k, CL_MON] and phi[k] < 0.0:
                        phi0 = phi_start[k]
                        if phi0 < 0.0:
                            tau[k] = 0.0
                        else:
                            tau[k] = locate_event(ci, cm, cp, cl, clf, mk, mon, c, k, n, ns, nh, fp, sc, sa, sb, t, h,
                                                  phi0, phi[k], z, zd, zdd, z1, zd1, zdd1, src1, rhs, sol, L, hertz)
                        tau_min = min(tau_min, tau[k])
                h = tau_min
                if h > 0.0:
                    sources(ns, nh, omega, sc, sa, sb, t + h, src1)
                    factor_effective(ci, cm, c, beta, gamma, h, L)
                    layer_step(ci, cm, cp, c, beta, gamma, h, CHOLESKY, L, n, src1, z, zd, zdd,
                               z1, zd1, zdd1, rhs, sol, cl, clf, mk, mon, hertz)
                    # (the gaps' values too: only the forces' and overlaps' are used, by the peaks)
                    monitors(cl, clf, mk, mon, c, n, ns, ncl, gap_noise, z1, zd1, zdd1, src1, phi, hertz)
                else:
                    copy_state(n, z, zd, zdd, src0, z1, zd1, zdd1, src1)
            if h > 0.0:
                diverged = False
                for j in range(ci[c, CI_NF]):
                    if not (abs(z1[j]) <= x_limit):
                        diverged = True
                if diverged:
                    scatter(ci, c, n, z1, zd1, zdd1, x, v, a)
                    fst[F_T] = t + h
                    return DIVERGED
                # outputs inside (t, t + h]
                if every:
                    if ist[I_NOUT] >= rows:
                        status = OUTPUT_FULL
                        break
                    record_row(ci, cl, clf, mk, mon, c, n, ns, ncl, gap_noise, t + h, z1, zd1, zdd1, src1,
                               out_t, out_q, out_F, out_c, ist[I_NOUT], hertz)
                    ist[I_NOUT] += 1
                else:
                    t_out = ist[I_NEXT_OUT] * out_dt  # the next output instant: a call only when one is due
                    if (t_out <= t + h + 1e-9 * dt and t_out <= t_end + 1e-9 * dt
                            and not step_rows(ci, cl, clf, mk, mon, c, n, ns, nh, ncl, fp, sc, sa, sb, t, h, z, zd, zdd,
                                              z1, zd1, zdd1, zo, zdo, zddo, srco, out_t, out_q, out_F, out_c, ist, hertz)):
                        status = OUTPUT_FULL
                        break
                # peaks at the step's end
                track_peaks(cl, clf, mk, mon, c, n, ns, ncl, gap_noise, t + h >= t_rev, phi, z1, zd1, zdd1, src1,
                            peak, hertz)
                ist[I_STEPS] += 1
                copy_state(n, z1, zd1, zdd1, src1, z, zd, zdd, src0)
                t = t + h
                fst[F_T] = t
                if abs(t - target) <= 1e-9 * dt:
                    t = arrive(ist, fst, target, grid_next, k_grid, j_target)
            if fired:
                event = True
                break
        scatter(ci, c, n, z, zd, zdd, x, v, a)
        if not event:
            return status
        # ---- the events at t (within the tolerance) ----
        new_c = take_events(ip, fp, cl, clf, mass, c, t, h, tau, closing, x, v, src0, ev_f, ev_i, ist, fst, momentum)
        if new_c < 0:
            return CHATTER
        ist[I_CFG] = new_c
        ist[I_NEED_SETTLE] = 1
        fst[F_FINE_UNTIL] = t + fp[FP_REFWIN]
