"""The layout of the Newmark kernel's arrays: slot numbers, codes and the law switches (no numba).

:mod:`vtool.solvers.model.contact` builds the tables in this layout,
:mod:`vtool.solvers.newmark.backend` reads the kernel's state and status codes in
it, and the kernel (:mod:`vtool.solvers.newmark.kernel`) computes on them; the
arrays travel in the records of :mod:`vtool.solvers.newmark.records`. numba
freezes these values into the compiled code: this file is one of the sources
whose digest names the cache folder (:func:`vtool.numba_cache.kernel_sources`),
so an edit here starts an empty cache.
"""

from __future__ import annotations

import numpy as np

# ----- slots of the integer and float parameter vectors -----
IP_N, IP_NCL, IP_NS, IP_NH, IP_EVERY, IP_ZSTICK, IP_ZSTOP = range(7)
IP_SIZE = 8
(FP_BETA, FP_GAMMA, FP_DT, FP_TEND, FP_OUTDT, FP_OMEGA, FP_TTOL, FP_ZWIN, FP_XLIM, FP_VREST,
 FP_GAPNOISE, FP_REFINE, FP_REFWIN, FP_FTOL, FP_TREV, FP_CHUNK) = range(16)
FP_SIZE = 16
# FP_CHUNK: a chunk's length (s) when the kernel goes on past a chunk's end by itself (nobody to report
# progress to or to ask about a cancel), 0.0 when it returns CHUNK_END to its caller there
# clearance table columns (int) and float columns
CL_AHEAD, CL_BEHIND, CL_SRC, CL_MON, CL_PIN, CL_BIT, CL_LAW, CL_SOFT = range(8)
CL_SIZE = 8  # CL_SOFT: SOFT_LINEAR or SOFT_HERTZ for a compliant clearance (no impact, no tie), else 0
SOFT_LINEAR, SOFT_HERTZ = 1, 2
# float columns: restitution, SCALE; Hertz stiffness and exponent; approach velocity of the contact; the
# gap's opening and sense (gap = sense (x_ahead - x_behind) + opening: ClearanceSpec.opening, 0 and 1 by default)
CLF_E, CLF_SCALE, CLF_HK, CLF_HN, CLF_HV, CLF_OPEN, CLF_SIGN = range(7)
CLF_SIZE = 7
# impact laws
LAW_MOMENTUM, LAW_LOCAL, LAW_THESIS = range(3)
# event kinds
EV_OPENED, EV_CLOSED, EV_RELEASED = np.int64(0), np.int64(1), np.int64(2)  # np.int64: add_event compiles once
# configuration integer table: m, nf, source coupling, closed Hertz contacts, the rows of the
# standard and refined step operators (nf free rows, then the force rows: see CP_RAW), whether those
# rows read the sources, then kept[n], group[n], source of each z index[n]
CI_M, CI_NF, CI_SRC, CI_HERTZ, CI_ROWS, CI_SRCSTEP = range(6)
CI_HEAD = 6
# configuration matrices
CM_MFF, CM_CFF, CM_KFF, CM_SINV, CM_SINVF, CM_MINVFF = range(6)
CM_SIZE = 6
# step operators, transposed: cp[c, plane, part, :, f] for free z index f (each column's coefficients
# on the free rows side by side: see :func:`apply_operator`); plane CP_RAW holds R, whose parts are
# C_FF, K_FF, the (M, C, K) columns of each prescribed z index p (at 3p, 3p + 1, 3p + 2) and the
# sources' pull S (3 per source), so that the free rows' ΔP is R·(ż, z, (z̈, ż, z)_P, src); planes
# CP_STD and CP_FINE hold G = S⁻¹R of the standard and the refined step, so that a step with a stored
# inverse computes z̈_F = -G·(ż̃, z̃, …) in one product (see :func:`apply_operator`). Parts, not column
# offsets: an index that is a loop counter needs no negative-index fix-up. The two step planes also
# hold, after the nf free rows, one row per closed rigid clearance (its MK_ROW): the contact force at
# the step's end less its constant, as the same product gives it from the step's predictor (the force
# row w on (z, ż, z̈, sources) with the step's z̈_F = -G·y substituted), so that a quiet step gets its
# force monitors from the vector pass it makes anyway (see ``ConfigurationTables._force_rows``). The
# last dimension is n + ncl.
CP_RAW, CP_STD, CP_FINE = range(3)
CP_SIZE = 3
PART_C, PART_K, PART_P, PART_S = range(4)
PART_SIZE = 4
# monitor per (configuration, clearance): (kind, ahead z index, behind z index or -1 - source, m, and for
# a closed rigid clearance its force's row in the step operators' output, else -1)
MK_KIND, MK_AHEAD, MK_BEHIND, MK_M, MK_ROW = range(5)
MK_SIZE = 5
MK_NONE, MK_GAP, MK_FORCE, MK_OVERLAP = range(4)  # MK_OVERLAP: a closed compliant clearance
# peak rows: contact force over the run, after the first revolution, overlap of compliant contacts
PEAK_ALL, PEAK_LATE, PEAK_OVERLAP = range(3)
# run status
FINISHED, CHUNK_END, NEED_CONFIG, OUTPUT_FULL, DIVERGED, CHATTER = range(1, 7)
# integer and float state slots
I_CFG, I_NOUT, I_NEV, I_STEPS, I_RAPID, I_GRID, I_NEXT_OUT, I_NEED_SETTLE, I_WANT_CFG, I_STARTED, I_SUB = range(11)
I_SIZE = 11  # I_SUB: refined steps taken since the grid point I_GRID (the refined steps' own grid)
F_T, F_LAST_EVENT, F_CHUNK_END, F_FINE_UNTIL = range(4)
F_SIZE = 4
# the run loop's scratch (records.scratch): a layer state's rows (z, ż, z̈), the layer states and the
# sources' instants (a step's start and end, an output row), the per-clearance rows
Z, ZD, ZDD = range(3)
Y_NOW, Y_END, Y_OUT = range(3)
SRC_NOW, SRC_END, SRC_OUT = range(3)
PHI, PHI_START, TAU = range(3)
RHS, SOL = range(2)  # the rows of the scratch's system: a step's right side and its solution


def series_table(const: np.ndarray, cos: np.ndarray, sin: np.ndarray) -> np.ndarray:
    """The sources' Fourier series as the kernel reads them: row s is source s's constant, then its
    nh cosine and its nh sine coefficients (one array of the problem's record, not three)."""
    return np.ascontiguousarray(np.hstack([const[:, None], cos, sin]), dtype=np.float64)


def laws(cl: np.ndarray) -> tuple[bool | None, bool | None]:
    """The ``hertz`` and ``momentum`` switches of the kernel's entry points for clearance table ``cl``:
    True when some clearance uses that law, None when none does. numba prunes the branches under a
    None switch before typing, so each law pair compiles and caches a kernel of its own (and the
    plain-Python reference takes the same branches)."""
    hertz = bool(np.any(cl[:, CL_SOFT] == SOFT_HERTZ))
    momentum = bool(np.any((cl[:, CL_LAW] == LAW_MOMENTUM) & (cl[:, CL_SOFT] == 0)))
    return (True if hertz else None), (True if momentum else None)

