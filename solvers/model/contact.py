"""The contact problem every back end shares: clearances, sources, configurations, impact laws.

Built from a :class:`~vtool.solvers.model.mechanism.Mechanism`, a :class:`ContactProblem`
holds, as the flat arrays the compiled kernel (:mod:`vtool.solvers.newmark.kernel`)
reads:

* the clearance table (ahead and behind coordinates, source, monitored,
  pinned, configuration bit, impact law) with restitution and SCALE;
* the mass matrix and its inverse (impacts);
* the prescribed motions as Fourier series (:mod:`vtool.solvers.model.sources`);
* per configuration, built the first time a run reaches it: the ordered
  layer (free coordinates first, then the prescribed ones), its matrices,
  the coupling to the prescribed coordinates, the monitor rows (contact
  force of every closed clearance on (z, ż, z̈, sources), gap of every open
  one), and, for the Newmark back end, the effective-matrix inverses of the
  standard and refined steps.

The event rules (located sign changes, earliest first; impact laws;
:func:`~vtool.solvers.newmark.kernel.release_pulling` after every transition; sticking
and stopping of chattering contacts) are the kernel's functions, called by
every back end: a back end only integrates between events.

Configuration tables do not depend on the cam speed, so a
:class:`ConfigurationTables` is kept on the mechanism and reused by every
run at any speed (a sweep builds each configuration once per worker).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vtool.errors import RunError
from vtool.solvers.model.configurations import (
    clearance_bit,
    compliant_terms,
    configuration_label,
    hertz_row,
    internal_force_coefficients,
    kernel_opening,
    mask_of,
    partition,
    sources,
    unit_source,
)
from vtool.solvers.model.hertz import kernel_restitution
from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.model.sources import SourceSeries
from vtool.solvers.model.spec import (
    ENABLED,
    HERTZ,
    INTERNAL,
    LINEAR,
    LOCAL,
    MOMENTUM,
    PINNED,
    RIGID,
    THESIS,
)
from vtool.solvers.newmark import layout
from vtool.solvers.newmark.records import Output, Problem, State, Tables, mask_hash
from vtool.solvers.trace import EVENT_KINDS, OPENED, TraceBuilder

LAW_CODES = {MOMENTUM: layout.LAW_MOMENTUM, LOCAL: layout.LAW_LOCAL, THESIS: layout.LAW_THESIS}
SOFT_CODES = {RIGID: 0, LINEAR: layout.SOFT_LINEAR, HERTZ: layout.SOFT_HERTZ}


def source_series(mechanism: Mechanism) -> SourceSeries:
    """The cam and the seat as Fourier series at the mechanism's cam speed.

    The cam's lift L(θ) = c0 + Σ (a_k cos kθ + b_k sin kθ) rides on the
    static start's base (XZERO - c0 for the thesis' harmonic cam, where
    c0 = b_1 = A), so q_cam = offset - c0 + L(ωt).
    """
    spec = mechanism.spec
    c0, a, b = cam_lift_series(mechanism)
    numbers = [number for number, _, _ in sources(spec)]
    ns, nh = len(numbers), max(len(a), 1)
    const, cos, sin = np.zeros(ns), np.zeros((ns, nh)), np.zeros((ns, nh))
    const[0] = mechanism.start.cam_offset
    cos[0, :len(a)], sin[0, :len(b)] = a, b
    if spec.seat is not None:
        const[1] = spec.seat.position
    if unit_source(spec) >= 0:
        const[unit_source(spec)] = 1.0
    return SourceSeries(mechanism.omega, tuple(numbers), const, cos, sin)


def cam_lift_series(mechanism: Mechanism) -> tuple[float, np.ndarray, np.ndarray]:
    """(c0, a_k, b_k) of the cam lift; the thesis' harmonic cam is c0 = A, b_1 = A."""
    from vtool.solvers.model.cam import lift_series

    return lift_series(mechanism.spec.cam)


@dataclass
class OrderedLayer:
    """A configuration's layer, free coordinates first: what the piecewise back ends integrate."""

    mask: int
    M: np.ndarray  # m x m, ordered
    C: np.ndarray
    K: np.ndarray
    nf: int
    kept: np.ndarray  # full coordinate (0-based) of each z index
    group: np.ndarray  # z index of each full coordinate
    source: np.ndarray  # source index of each prescribed z index (nf..m-1)
    S: np.ndarray  # m x 3 ns: the sources' (x, v, a) pull on each z index through closed compliant contacts

    @property
    def m(self) -> int:
        return int(self.M.shape[0])


class ConfigurationTables:
    """Per-configuration arrays for the kernel, filled lazily by :meth:`build` (speed-independent).

    Storage grows with the configurations a run visits, not with the 2^ncl a
    mechanism could reach: each built configuration has a slot (row) of the
    arrays ``ci``, ``cm``, ``cp``, ``mk``, ``mon``, given by :attr:`slots` (mask ->
    slot) and, for the kernel, by the open-addressing map ``index``
    (:class:`vtool.solvers.newmark.records.Tables`). Both double when full; the
    kernel's record is then made again (:meth:`record`).
    """

    # the slot arrays, (re)made by _allocate
    ci: np.ndarray
    cm: np.ndarray
    cp: np.ndarray
    mk: np.ndarray
    mon: np.ndarray

    def __init__(self, mechanism: Mechanism) -> None:
        spec = mechanism.spec
        self.mechanism = mechanism
        n, ncl, ns = spec.n_coordinates, len(spec.clearances), len(sources(spec))
        self.n, self.ncl, self.ns = n, ncl, ns
        self.slots: dict[int, int] = {}
        self.index = np.full((8, 2), -1, dtype=np.int64)
        self._allocate(4)
        self.layers: dict[int, OrderedLayer] = {}
        self.step: tuple[float, float, float, float] | None = None  # (dt, beta, gamma, fine) of the inverses
        self._record: Tables | None = None

    def _allocate(self, count: int) -> None:
        """Room for ``count`` configurations; the built ones are kept."""
        n, ncl, ns = self.n, self.ncl, self.ns

        def grown(old: np.ndarray | None, shape: tuple[int, ...], dtype: type) -> np.ndarray:
            new: np.ndarray = np.zeros((count, *shape), dtype=dtype)
            if old is not None:
                new[:old.shape[0]] = old
            return new

        self.ci: np.ndarray = grown(getattr(self, "ci", None), (layout.CI_HEAD + 3 * n,), np.int64)
        self.cm: np.ndarray = grown(getattr(self, "cm", None), (layout.CM_SIZE, n, n), float)
        self.cp: np.ndarray = grown(getattr(self, "cp", None),  # layout.CP_RAW
                                    (layout.CP_SIZE, layout.PART_SIZE, 3 * max(n, ns), n + ncl), float)
        self.mk: np.ndarray = grown(getattr(self, "mk", None), (ncl, layout.MK_SIZE), np.int64)
        self.mon: np.ndarray = grown(getattr(self, "mon", None), (ncl, 3 * n + 3 * ns + 1 + ncl), float)
        self._record = None

    def _slot(self, mask: int) -> int:
        """A new slot for configuration ``mask`` (the arrays grown as needed); the kernel finds it once
        it is filled (:meth:`_publish`)."""
        slot = len(self.slots)
        if slot >= self.ci.shape[0]:
            self._allocate(2 * self.ci.shape[0])
        self.slots[mask] = slot
        return slot

    def _publish(self, mask: int) -> None:
        """Configuration ``mask`` into the kernel's index (grown to stay at most half full)."""
        if 2 * len(self.layers) > self.index.shape[0]:
            self.index = np.full((2 * self.index.shape[0], 2), -1, dtype=np.int64)
            for known in self.layers:
                self._insert(known, self.slots[known])
        else:
            self._insert(mask, self.slots[mask])
        self._record = None

    def _insert(self, mask: int, slot: int) -> None:
        capacity = self.index.shape[0]
        h = mask_hash(mask, capacity)
        while self.index[h, 0] >= 0:
            h = (h + 1) & (capacity - 1)
        self.index[h] = (mask, slot)

    def record(self) -> Tables:
        """The kernel's record of these tables (the arrays as they are now)."""
        if self._record is None:
            self._record = Tables(self.index, self.ci, self.cm, self.cp, self.mk, self.mon)
        return self._record

    def of(self, mask: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Built configuration ``mask``'s rows (ci, cm, cp, mk, mon)."""
        slot = self.slots[mask]
        return self.ci[slot], self.cm[slot], self.cp[slot], self.mk[slot], self.mon[slot]

    def use_step(self, dt: float, beta: float, gamma: float, fine: float) -> None:
        """Make the stored effective inverses those of this step (rebuilt for every built configuration)."""
        step = (dt, beta, gamma, fine)
        if self.step == step:
            return
        self.step = step
        for mask in self.layers:
            self._inverses(mask)

    def _inverses(self, mask: int) -> None:
        if self.step is None:
            return
        dt, beta, gamma, fine = self.step
        ci, cm, cp, _, _ = self.of(mask)
        nf = int(ci[layout.CI_NF])  # G = S⁻¹R, part by part, stored transposed as R is (see layout.CP_RAW)
        if nf:
            M, C, K = cm[layout.CM_MFF, :nf, :nf], cm[layout.CM_CFF, :nf, :nf], cm[layout.CM_KFF, :nf, :nf]
            cm[layout.CM_SINV, :nf, :nf] = np.linalg.inv(M + gamma * dt * C + beta * dt * dt * K)
            cm[layout.CM_SINVF, :nf, :nf] = np.linalg.inv(M + gamma * fine * C + beta * fine * fine * K)
            raw = np.ascontiguousarray(np.swapaxes(cp[layout.CP_RAW, :, :, :nf], 1, 2))  # R's free rows
            cp[layout.CP_STD, :, :, :nf] = np.swapaxes(cm[layout.CM_SINV, :nf, :nf] @ raw, 1, 2)
            cp[layout.CP_FINE, :, :, :nf] = np.swapaxes(cm[layout.CM_SINVF, :nf, :nf] @ raw, 1, 2)
        self._force_rows(mask, beta, gamma, ((layout.CP_STD, dt), (layout.CP_FINE, fine)))

    def _force_rows(self, mask: int, beta: float, gamma: float,
                    planes: tuple[tuple[int | np.int64, float], ...]) -> None:
        """The force rows of the step operators (``layout.CP_RAW``): each closed rigid clearance's contact
        force at a step's end, less its constant, from the step's predictor y = (ż̃_F, z̃_F, (z̈, ż, z)_P, src).

        With the force row w = (w_z, w_ż, w_z̈, w_s, w_0) on the layer (``mon``) and a Newmark step of
        length h, the free rows end at z_F = z̃_F + βh² z̈_F, ż_F = ż̃_F + γh z̈_F, with z̈_F = -G y;
        the prescribed rows are y's own. So

            F - w_0 = d·y + uᵀ z̈_F = (d - Gᵀu)·y,   u = βh² w_z,F + γh w_ż,F + w_z̈,F,

        where d holds w's coefficients on y's entries (w_ż,F, w_z,F, then (w_z̈, w_ż, w_z)_P, w_s). The
        kernel's product gives out = -R y for a stored row R, so the row stored is Gᵀu - d. The terms on a
        source that a prescribed index follows are moved onto that index's columns (the same values), so
        that the step reads the source columns only where a term is left (``CI_SRCSTEP``): on 1A the
        quiet step was 0.91 of one that read them (``bench_step_ab.py``). The same number as
        :func:`vtool.solvers.newmark.kernel.forces.linear_force` of the step's end, up to round-off.
        """
        n, ns = self.n, self.ns
        ci, _, cp, mk, mon = self.of(mask)
        nf, m = int(ci[layout.CI_NF]), int(ci[layout.CI_M])
        np_ = m - nf
        reads_sources = bool(ci[layout.CI_SRC])
        for plane, h in planes:
            bx, gv = beta * h * h, gamma * h
            for k in range(self.ncl):
                row = int(mk[k, layout.MK_ROW])
                if mk[k, layout.MK_KIND] != layout.MK_FORCE or row < 0:
                    continue
                w = mon[k]
                wz, wzd, wzdd, ws = w[:n], w[n:2 * n], w[2 * n:3 * n], w[3 * n:3 * n + 3 * ns]
                u = bx * wz[:nf] + gv * wzd[:nf] + wzdd[:nf]
                d = np.zeros(cp.shape[1:3])
                d[layout.PART_C, :nf], d[layout.PART_K, :nf] = wzd[:nf], wz[:nf]
                d[layout.PART_P, 0:3 * np_:3] = wzdd[nf:m]
                d[layout.PART_P, 1:3 * np_:3] = wzd[nf:m]
                d[layout.PART_P, 2:3 * np_:3] = wz[nf:m]
                d[layout.PART_S, :3 * ns] = ws
                cp[plane, :, :, row] = cp[plane, :, :, :nf] @ u - d
                # a source that a prescribed z index follows is that index's (z, ż, z̈) already: its
                # terms move onto the prescribed columns, and the step reads no source columns for them
                for p in range(np_):
                    s = int(ci[layout.CI_HEAD + 2 * n + nf + p])
                    for q in range(3):  # the source's (x, v, a) onto the prescribed (z, ż, z̈): 3p + 2 - q
                        cp[plane, layout.PART_P, 3 * p + 2 - q, row] += cp[plane, layout.PART_S, 3 * s + q, row]
                        cp[plane, layout.PART_S, 3 * s + q, row] = 0.0
                reads_sources = reads_sources or bool(np.any(cp[plane, layout.PART_S, :, row]))
        ci[layout.CI_SRCSTEP] = int(reads_sources)

    def of_new(self, mask: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """A new slot's rows for configuration ``mask`` (see :meth:`of`)."""
        self._slot(mask)
        return self.of(mask)

    def build(self, mask: int) -> OrderedLayer:
        """Partition configuration ``mask`` and fill its rows (see the module doc)."""
        if mask in self.layers:
            return self.layers[mask]
        mechanism, n = self.mechanism, self.n
        part = partition(mechanism, mask)
        layer = part.layer
        order = part.free + part.prescribed
        position = np.empty(layer.size, dtype=np.int64)
        position[order] = np.arange(layer.size)
        m, nf = layer.size, len(part.free)
        group = position[part.group]
        kept = np.array([layer.kept[col] - 1 for col in order], dtype=np.int64)
        source = np.array(part.sources, dtype=np.int64)
        ix = np.ix_(order, order)
        springs = compliant_terms(mechanism, mask)
        M_o = layer.M[ix]
        C_o = (part.C + springs.layer_C(layer.T))[ix]
        K_o = (layer.K + springs.layer_K(layer.T))[ix]
        S_o = (layer.T.T @ springs.S)[order]
        ci, cm, raw, _, _ = self.of(mask) if mask in self.slots else self.of_new(mask)
        raw = raw[layout.CP_RAW]  # Rᵀ: see layout.CP_RAW
        ci[layout.CI_M], ci[layout.CI_NF] = m, nf
        ci[layout.CI_ROWS] = nf  # and one more per closed rigid clearance (_monitors)
        head = layout.CI_HEAD
        ci[head:head + m] = kept
        ci[head + n:head + 2 * n] = group
        ci[head + 2 * n + nf:head + 2 * n + m] = source
        cm[layout.CM_MFF, :nf, :nf] = M_o[:nf, :nf]
        cm[layout.CM_CFF, :nf, :nf] = C_o[:nf, :nf]
        cm[layout.CM_KFF, :nf, :nf] = K_o[:nf, :nf]
        if nf:
            cm[layout.CM_MINVFF, :nf, :nf] = np.linalg.inv(M_o[:nf, :nf])
        raw[layout.PART_C, :nf, :nf] = C_o[:nf, :nf].T
        raw[layout.PART_K, :nf, :nf] = K_o[:nf, :nf].T
        raw[layout.PART_P, 0:3 * (m - nf):3, :nf] = M_o[:nf, nf:].T
        raw[layout.PART_P, 1:3 * (m - nf):3, :nf] = C_o[:nf, nf:].T
        raw[layout.PART_P, 2:3 * (m - nf):3, :nf] = K_o[:nf, nf:].T
        raw[layout.PART_S, :S_o.shape[1], :nf] = S_o[:nf].T
        ci[layout.CI_SRC] = int(bool(S_o[:nf].any()))
        ci[layout.CI_SRCSTEP] = ci[layout.CI_SRC]  # and where a force row reads the sources (_force_rows)
        ci[layout.CI_HERTZ] = int(bool(springs.hertz))
        self._monitors(mask, part, group, m, springs)
        ordered = OrderedLayer(mask, M_o, C_o, K_o, nf, kept, group, source, S_o)
        self.layers[mask] = ordered
        self._inverses(mask)
        self._publish(mask)
        return ordered

    def _monitors(self, mask: int, part, group: np.ndarray, m: int, springs) -> None:
        """Force rows of the closed clearances, gap references of the open monitored ones.

        A rigid external contact's force is the row force r at its ahead
        coordinate less the compliant contacts' forces on that coordinate; a
        compliant contact's force is its spring and dashpot (``springs``), and
        its monitor is the overlap of the pair."""
        mechanism, spec, n, ns = self.mechanism, self.mechanism.spec, self.n, self.ns
        layer = part.layer
        kept_full = [k - 1 for k in layer.kept]
        MT = mechanism.M @ layer.T
        row_x, row_v, row_a = mechanism.K @ layer.T, MT @ np.linalg.solve(layer.M, part.C), MT
        source_of = {number: s for s, (number, _, _) in enumerate(sources(spec))}
        ci, _, _, mk_all, mon_all = self.of(mask)
        for index, c in enumerate(spec.clearances):
            mk, mon = mk_all[index], mon_all[index]
            behind = int(group[c.behind - 1]) if c.kind == INTERNAL else -1 - source_of[c.behind]
            if mask & clearance_bit(spec, index):
                frow = np.zeros(3 * n + 3 * ns)
                hertz = mon[3 * n + 3 * ns + 1:]  # per unit force of each closed Hertz contact
                if c.contact == LINEAR:
                    frow[:] = springs.force[index]
                elif c.contact == HERTZ:
                    frow[:] = hertz_row(mechanism, index)
                elif c.kind == INTERNAL and c.state == ENABLED:
                    fx, fv, fs, fh = internal_force_coefficients(mechanism, mask, c.ahead, c.behind)
                    frow[:n], frow[n:2 * n], frow[3 * n:] = fx, fv, fs.ravel()
                    for j, coefficient in fh.items():
                        hertz[j] = coefficient
                else:  # the row force r at the ahead coordinate (see vtool.solvers.model.configurations)
                    i = c.ahead - 1
                    for j, full in enumerate(kept_full):
                        frow[full] += row_x[i, j]
                        frow[n + full] += row_v[i, j]
                        frow[2 * n + full] += row_a[i, j]
                    frow[:n] += springs.K[i]
                    frow[n:2 * n] += springs.C[i]
                    frow[3 * n:] += springs.S[i]
                    for j, w in springs.hertz.items():  # less the Hertz forces F_j w_j on this coordinate
                        hertz[j] = -w[i]
                for part_index in range(3):  # fold full coordinates onto the z indices
                    np.add.at(mon[part_index * n:(part_index + 1) * n], group,
                              frow[part_index * n:(part_index + 1) * n])
                mon[3 * n:3 * n + 3 * ns] = frow[3 * n:]
                kind = layout.MK_FORCE if c.rigid else layout.MK_OVERLAP
                row = -1
                if c.rigid:  # its row in the step operators (see layout.CP_RAW), after the free rows
                    row = int(ci[layout.CI_ROWS])
                    ci[layout.CI_ROWS] = row + 1
                mk[:] = (kind, int(group[c.ahead - 1]), behind, m, row)
            elif c.state == ENABLED:
                mk[:] = (layout.MK_GAP, int(group[c.ahead - 1]), behind, m, -1)


def event_buffers(rows: int) -> tuple[np.ndarray, ...]:
    """Output buffers for events only (a kernel Output record's fields; no rows, no peaks)."""
    return (np.zeros(0), np.zeros((3, 0, 0)), np.zeros((0, 0)), np.zeros(0, dtype=np.int64),
            np.zeros((rows, 2)), np.zeros((rows, 4), dtype=np.int64), np.zeros((3, 0)))


@dataclass(frozen=True)
class EventRules:
    """Settings of the event rules every back end applies (defaults from the mechanism's scales)."""

    rest_velocity: float | None = None  # length/s; default 1e-5 of the velocity scale
    zeno_stick: int = 20
    zeno_stop: int = 400


@dataclass(frozen=True)
class LayerOperator:
    """z̈_F = on_z z + on_zd ż + on_aP z̈_P + on_src s: a configuration's equations solved for the free
    accelerations (M_FF⁻¹ times the layer's rows), with the index maps between the full coordinates and
    the layer's (free ``kept``, prescribed ``source``, ``group``)."""

    free: np.ndarray  # full coordinate of each free z index
    prescribed: np.ndarray  # 3 x the source of each prescribed z index (its x in the sources' vector)
    group: np.ndarray  # z index of each full coordinate
    on_z: np.ndarray
    on_zd: np.ndarray
    on_aP: np.ndarray
    on_src: np.ndarray

    @classmethod
    def of(cls, layer: OrderedLayer, n: int) -> LayerOperator:
        nf = layer.nf
        solve = np.linalg.inv(layer.M[:nf, :nf])
        return cls(layer.kept[:nf].astype(np.int64), 3 * layer.source.astype(np.int64), layer.group,
                   -solve @ layer.K[:nf], -solve @ layer.C[:nf], -solve @ layer.M[:nf, nf:], -solve @ layer.S[:nf])


class ContactProblem:
    """The clearances, sources, configurations and impact laws of one mechanism at one cam speed."""

    def __init__(self, mechanism: Mechanism, rules: EventRules | None = None) -> None:
        rules = rules or EventRules()
        spec = mechanism.spec
        self.mechanism = mechanism
        self.spec = spec
        self.rules = rules
        self.n, self.ncl = spec.n_coordinates, len(spec.clearances)
        self.tables = mechanism.shared(ConfigurationTables, lambda: ConfigurationTables(mechanism))
        self.series = source_series(mechanism)
        self.ns, self.nh = self.series.n_sources, self.series.n_harmonics
        self.series_table = layout.series_table(self.series.const, self.series.cos, self.series.sin)
        self.source_numbers = self.series.numbers
        cl = np.zeros((self.ncl, layout.CL_SIZE), dtype=np.int64)
        clf = np.zeros((self.ncl, layout.CLF_SIZE))
        for k, c in enumerate(spec.clearances):
            external = c.behind > self.n or c.behind == 0  # 0: the ground, the unit source
            cl[k] = (c.ahead - 1, -1 if external else c.behind - 1, self.series.index(c.behind) if external else -1,
                     int(c.state == ENABLED), int(c.state == PINNED), clearance_bit(spec, k),
                     LAW_CODES[spec.impact_law(c)], SOFT_CODES[c.contact])
            # a Hertz contact's slot holds the e' whose a = 3(1 - e')/2 rebounds at c.restitution (hertz.py)
            restitution = kernel_restitution(c.restitution) if c.contact == HERTZ else c.restitution
            clf[k, :layout.CLF_HV] = (restitution, spec.contact.rocker_scale, c.contact_stiffness,
                                      c.contact_exponent)
            clf[k, layout.CLF_OPEN], clf[k, layout.CLF_SIGN] = kernel_opening(c), c.sense
        self.cl, self.clf = cl, clf
        self.hertz, self.momentum = layout.laws(cl)  # the kernel's law switches
        self.mass = mechanism.mass_and_inverse
        self.omega = mechanism.omega
        self.omega_max = mechanism.highest_frequency
        x_scale = max(spec.cam.amplitude + abs(mechanism.start.cam_offset), 1e-9)
        self.x_scale = x_scale
        self.rest_velocity = rules.rest_velocity or 1e-5 * self.velocity_scale()
        self.clf[:, layout.CLF_HV] = self.rest_velocity  # a Hertz contact's approach velocity, set at closing
        self.gap_noise = 1e-13 * x_scale
        self.zeno_window = 1e-3 * 2 * math.pi / self.omega_max
        self.start_mask = mask_of(spec, tuple(spec.initial.closed) + mechanism.start.closed)  # and closed coils

    @classmethod
    def for_run(cls, mechanism: Mechanism, rules: EventRules | None = None) -> ContactProblem:
        """The contact problem of one run: a copy of the mechanism's problem at this cam speed and these
        rules, built at its first run and kept with the mechanism (:meth:`Mechanism.kept`), with the
        run's own mechanism and its own ``clf`` (the only table the kernel writes: a Hertz contact's
        approach velocity). Everything else depends on the mechanism, the cam speed and the rules alone."""
        rules = rules or EventRules()
        kept = mechanism.kept(("contact problem", mechanism.omega, rules), lambda: cls(mechanism, rules))
        problem = object.__new__(cls)  # a shallow copy (copy.copy's protocol took as long as the rest of for_run)
        problem.__dict__.update(kept.__dict__)
        problem.mechanism, problem.spec, problem.clf = mechanism, mechanism.spec, kept.clf.copy()
        if mechanism.start_mask is not None:  # a carried start (Mechanism.with_start)
            problem.start_mask = mechanism.start_mask
        return problem

    def velocity_scale(self) -> float:
        """Cam amplitude times the larger of the cam speed and the lowest elastic frequency."""
        return self.spec.cam.amplitude * max(self.omega, self.mechanism.lowest_start_frequency)

    def force_tolerance(self) -> float:
        """Contact forces above -this count as pushing when a transition is settled."""
        return 1e-9 * max(abs(self.mechanism.start.follower_force), 1e-300) + 1e-12

    def parameters(self, *, dt: float = 1.0, beta: float = 0.25, gamma: float = 0.5, t_end: float = 0.0,
                   out_dt: float = 1.0, every_step: bool = False, time_tol: float = 1e-12,
                   refine: float = 1.0, refine_window: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """The kernel's integer and float parameter vectors."""
        ip = np.zeros(layout.IP_SIZE, dtype=np.int64)
        ip[layout.IP_N], ip[layout.IP_NCL], ip[layout.IP_NS], ip[layout.IP_NH] = self.n, self.ncl, self.ns, self.nh
        ip[layout.IP_EVERY] = int(every_step)
        ip[layout.IP_ZSTICK], ip[layout.IP_ZSTOP] = self.rules.zeno_stick, self.rules.zeno_stop
        fp = np.zeros(layout.FP_SIZE)
        fp[layout.FP_BETA], fp[layout.FP_GAMMA], fp[layout.FP_DT] = beta, gamma, dt
        fp[layout.FP_TEND], fp[layout.FP_OUTDT], fp[layout.FP_OMEGA] = t_end, out_dt, self.omega
        fp[layout.FP_TTOL], fp[layout.FP_ZWIN] = time_tol, self.zeno_window
        fp[layout.FP_XLIM], fp[layout.FP_VREST] = 1e3 * self.x_scale, self.rest_velocity
        fp[layout.FP_GAPNOISE], fp[layout.FP_REFINE], fp[layout.FP_REFWIN] = self.gap_noise, refine, refine_window
        fp[layout.FP_FTOL] = self.force_tolerance()
        fp[layout.FP_TREV] = 2 * math.pi / self.omega if self.omega > 0 else math.inf
        return ip, fp

    def build(self, mask: int) -> OrderedLayer:
        return self.tables.build(mask)

    def record(self, ip: np.ndarray | None = None, fp: np.ndarray | None = None) -> Problem:
        """The kernel's record of this problem with parameter vectors ``ip``, ``fp`` (default
        :meth:`parameters`' defaults)."""
        if ip is None or fp is None:
            ip, fp = self.parameters()
        return Problem(ip, fp, self.cl, self.clf, self.series_table, self.mass)

    def sources_at(self, t: float) -> np.ndarray:
        """(x, v, a) of every source at t, as the kernel's src vector."""
        from vtool.solvers.newmark import kernel  # numba: only the back ends that call it load it

        src = np.zeros(3 * self.ns)
        kernel.sources(self.series_table, self.omega, t, src)
        return src

    def impact(self, mask: int, closing: list[int], t: float, x: np.ndarray, v: np.ndarray,
               stick: bool = False) -> tuple[int, list[tuple[int, str, float, int, int]]]:
        """Apply the impact laws of the closing clearances at t to (x, v) in place.

        Returns the new configuration and the events (clearance, kind,
        relative velocity, before, after). The same kernel function the
        back ends call.
        """
        from vtool.solvers.newmark import kernel
        from vtool.solvers.newmark.records import Output

        flags = np.zeros(self.ncl, dtype=np.int64)
        flags[list(closing)] = 1  # the indices of the closing clearances
        events = Output(*event_buffers(4 * self.ncl + 4))
        state = State(x, v, np.zeros_like(x), np.zeros(layout.I_SIZE, dtype=np.int64), np.zeros(layout.F_SIZE))
        new = int(kernel.apply_impacts(self.record(), mask, flags, self.sources_at(t), state, stick, events, t,
                                       self.momentum))
        ev_f, ev_i = events.ev_f, events.ev_i
        return new, [(int(ev_i[r, 0]), EVENT_KINDS[int(ev_i[r, 1])], float(ev_f[r, 1]), int(ev_i[r, 2]),
                      int(ev_i[r, 3])) for r in range(int(state.ist[layout.I_NEV]))]

    # ----- the Python-level contract a back end integrates against (vtool.solvers.backends, point 4) -----
    # Rigid and linear contacts: a Hertz contact's force is the kernel's hertz_law (the Newmark and
    # piecewise back ends), so a back end written against these methods alone refuses one.

    def operator(self, mask: int) -> LayerOperator:
        """Configuration ``mask``'s equations as :meth:`accelerations` uses them (made once per mask)."""
        operators = self.__dict__.setdefault("_operators", {})
        if mask not in operators:
            operators[mask] = LayerOperator.of(self.build(mask), self.n)
        return operators[mask]

    def layer_vectors(self, mask: int, t: float, x: np.ndarray, v: np.ndarray,
                      a: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
        """The configuration's layer vectors (z, ż[, z̈]) in its order (free coordinates, then the prescribed
        ones from the sources at t), and the sources' (x, v, a) vector."""
        op, src = self.operator(mask), self.sources_at(t)
        parts = (x, v) if a is None else (x, v, a)
        return (*(np.concatenate((w[op.free], src[op.prescribed + i])) for i, w in enumerate(parts)), src)

    def accelerations(self, mask: int, t: float, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        """ẍ of every coordinate in configuration ``mask`` at t, from (x, v) of every coordinate:
        M_FF z̈_F = -(K_FF z_F + C_FF ż_F) - (M_FP z̈_P + C_FP ż_P + K_FP z_P) - S_F s(t)
        (F free, P prescribed; S the sources' pull through closed linear contacts)."""
        op, src = self.operator(mask), self.sources_at(t)
        z = np.concatenate((x[op.free], src[op.prescribed]))
        zd = np.concatenate((v[op.free], src[op.prescribed + 1]))
        aP = src[op.prescribed + 2]
        zdd = np.concatenate((op.on_z @ z + op.on_zd @ zd + op.on_aP @ aP + op.on_src @ src, aP))
        return zdd[op.group]

    def project(self, mask: int, t: float, x: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(x, v) made to satisfy configuration ``mask``'s ties: tied coordinates take their free
        coordinate's values, those on a source the source's."""
        layer = self.build(mask)
        z, zd, _ = self.layer_vectors(mask, t, x, v)
        return z[layer.group], zd[layer.group]

    def monitors(self, mask: int, t: float, x: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """Each clearance's monitor at t: its gap while open, its contact force while closed (a linear
        contact: its overlap), NaN where not monitored. An event is a monitored clearance's value going
        below zero (:attr:`monitored`)."""
        z, zd, zdd, src = self.layer_vectors(mask, t, x, v, a)
        values = np.full(self.ncl, np.nan)
        forces = self.contact_forces(mask, t, x, v, a)
        for k, (kind, ahead, behind) in enumerate(self.tables.of(mask)[3][:, :layout.MK_M]):
            if kind in (layout.MK_GAP, layout.MK_OVERLAP):
                other = z[behind] if behind >= 0 else src[3 * (-1 - behind)]
                gap = self.clf[k, layout.CLF_SIGN] * (z[ahead] - other) + self.clf[k, layout.CLF_OPEN]
                values[k] = (1.0 if kind == layout.MK_GAP else -1.0) * gap + self.gap_noise
            elif kind == layout.MK_FORCE:
                values[k] = forces[k]
        return values

    def contact_forces(self, mask: int, t: float, x: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """Each clearance's contact force at t (compression positive; 0 while open)."""
        z, zd, zdd, src = self.layer_vectors(mask, t, x, v, a)
        n, ns, m = self.n, self.ns, len(z)
        forces = np.zeros(self.ncl)
        _, _, _, mk, mon = self.tables.of(mask)
        for k, kind in enumerate(mk[:, layout.MK_KIND]):
            if kind in (layout.MK_FORCE, layout.MK_OVERLAP):
                row = mon[k]
                forces[k] = (row[:m] @ z + row[n:n + m] @ zd + row[2 * n:2 * n + m] @ zdd
                             + row[3 * n:3 * n + 3 * ns] @ src + row[3 * n + 3 * ns])
        return forces

    @property
    def monitored(self) -> np.ndarray:
        """Which clearances are watched for events (enabled ones)."""
        return self.cl[:, layout.CL_MON].astype(bool)

    def transitions(self, builder: TraceBuilder) -> Transitions:
        """The event rules for one run into ``builder`` (see :class:`Transitions`)."""
        return Transitions(self, builder)

    def label(self, mask: int) -> str:
        return configuration_label(self.spec, mask)

    def time_to_angle(self, t: float | np.ndarray) -> float | np.ndarray:
        """Cam angle in degrees at time t (s)."""
        return np.asarray(t) * self.omega * 180.0 / math.pi if isinstance(t, np.ndarray) else \
            t * self.omega * 180.0 / math.pi

    def angle_to_time(self, degrees: float) -> float:
        return degrees * math.pi / 180.0 / self.omega


class Transitions:
    """The shared event and impact rules of one run, as a back end calls them (plain Python; the
    Newmark kernel runs the same rules compiled):

    * :meth:`start`: the static start, its pulling contacts released (settled);
    * :meth:`apply`: at an event, open the closed clearances whose force reached zero, apply the impact
      laws of those whose gap closed (after ``zeno_stick`` rapid events, closing contacts stick), settle,
      record every event in the builder; ``zeno_stop`` rapid events stop the run (RunError).
    """

    def __init__(self, problem: ContactProblem, builder: TraceBuilder) -> None:
        from vtool.solvers.newmark import (
            kernel,  # the compiled rules (numba: imported by those who call them)
        )

        self.problem, self.builder = problem, builder
        self.rules = kernel
        self.record = problem.record()
        self.events = Output(*event_buffers(4 * problem.ncl + 4))
        self.ev_f, self.ev_i = self.events.ev_f, self.events.ev_i
        self.ist = np.zeros(layout.I_SIZE, dtype=np.int64)
        self.fst = np.zeros(layout.F_SIZE)
        self.rapid, self.last_event = 0, -math.inf

    def start(self) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
        """(configuration, x, v, a) at t = 0: the mechanism's static start, settled (fresh arrays)."""
        start = self.problem.mechanism.start
        x, v, a = start.q.copy(), start.qd.copy(), start.qdd.copy()
        mask = self.settle(self.problem.start_mask, 0.0, x, v, a)
        return mask, x, v, self.problem.accelerations(mask, 0.0, x, v)

    def settle(self, mask: int, t: float, x: np.ndarray, v: np.ndarray, a: np.ndarray) -> int:
        """Release the contacts that pull in configuration ``mask`` at t (events recorded); the new mask."""
        problem, tables, m = self.problem, self.problem.tables, self.problem.n
        while True:
            self.ist[layout.I_NEV] = 0
            result = int(self.rules.release_pulling(
                self.record, tables.record(), mask, t, State(x, v, a, self.ist, self.fst), problem.sources_at(t),
                self.events, np.zeros((3, m)), np.zeros(m), problem.hertz))
            self.take_events()
            if result >= 0:
                return result
            mask = -1 - result
            problem.build(mask)

    def take_events(self) -> None:
        count = int(self.ist[layout.I_NEV])
        self.builder.add_events(self.ev_f[:count], self.ev_i[:count])
        self.ist[layout.I_NEV] = 0

    def apply(self, mask: int, t: float, x: np.ndarray, v: np.ndarray, crossed: list[int],
              accelerations: bool = True) -> tuple[int, np.ndarray, np.ndarray, np.ndarray | None]:
        """The configuration and (x, v, a) after the events of the clearances ``crossed`` at t (a is None
        unless ``accelerations``: a back end that restarts from (x, v) alone skips its solve)."""
        problem = self.problem
        x, v = x.copy(), v.copy()
        bits = problem.cl[:, layout.CL_BIT]
        new = mask
        closing = np.zeros(problem.ncl, dtype=np.int64)
        for k in crossed:
            if mask & bits[k]:
                new &= ~int(bits[k])
            else:
                closing[k] = 1
        self.rapid = self.rapid + 1 if t - self.last_event <= problem.zeno_window else 0
        self.last_event = t
        if self.rapid >= problem.rules.zeno_stop:
            raise RunError(f"chattering contact at t = {t:.6g} s in configuration {problem.label(mask)}")
        src = problem.sources_at(t)
        for k in range(problem.ncl):
            if (mask & bits[k]) and not (new & bits[k]):
                u = 0.0
                if problem.cl[k, layout.CL_SOFT]:  # a linear contact's parts leave with their relative velocity
                    self.rules.shut_gap(problem.cl, problem.clf, k, x, src)
                    u = float(self.rules.gap_velocity(problem.cl, problem.clf, k, v, src))
                self.builder.add_event(t, k, OPENED, u, mask, new)
        if closing.any():
            self.ist[layout.I_NEV] = 0
            state = State(x, v, np.zeros_like(x), self.ist, self.fst)
            new = int(self.rules.apply_impacts(self.record, new, closing, src, state,
                                               self.rapid >= problem.rules.zeno_stick, self.events, t,
                                               problem.momentum))
            self.take_events()
        new = self.settle(new, t, x, v, np.zeros_like(x))  # (settle computes the accelerations it needs)
        return new, x, v, problem.accelerations(new, t, x, v) if accelerations else None
