"""The assembled mechanism: full matrices, contact layers built on demand, static start.

``assemble(spec)`` builds the full system (M, K) once. Contact layers (and
their eigenproblems and modal damping) are built the first time they are
asked for and then kept: a run builds only the layers it visits, and a
pinned clearance never produces a layer in which it is open.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Hashable
from functools import cached_property
from typing import Any, TypeVar

import numpy as np

from vtool.solvers.model.assembly import assemble_full
from vtool.solvers.model.damping import undamped_modes
from vtool.solvers.model.initial import StaticStart, static_start
from vtool.solvers.model.layers import Layer, build_layer, internal_layer_names, possible_layers
from vtool.solvers.model.spec import INTERNAL, LINEAR, MechanismSpec, RunSpec

#: Values a mechanism keeps for its runs (:meth:`Mechanism.kept`: a static start and a contact problem
#: per cam speed, ...) before it forgets them all: a sweep over speeds keeps its memory bounded.
DERIVED_KEPT = 64

T = TypeVar("T")


class Mechanism:
    """A valve train ready to solve: see the module docstring."""

    def __init__(self, spec: MechanismSpec, _shared: Mechanism | None = None) -> None:
        self.spec = spec
        self.start_mask: int | None = None  # a carried start's configuration (with_start); None: the preset's
        #: a carried start's nonlinear-element states (solvers/model/nonlinear.py); None: the elements' own
        self.start_states: np.ndarray | None = None
        if _shared is None:
            self.M, self.K = assemble_full(spec)
            self._layers: dict[frozenset[str], Layer] = {}
            self._lasting: dict[Hashable, Any] = {}  # speed-independent values, made on demand (see shared)
            # what a run derives from the mechanism and its cam speed alone (see kept)
            self._derived: dict[Any, Any] = {}
        else:  # the same mechanism run with other run settings: share what does not depend on them
            self.M, self.K, self._layers, self._lasting = _shared.M, _shared.K, _shared._layers, _shared._lasting
            self._derived = _shared._derived
            if "highest_frequency" in _shared.__dict__:
                self.__dict__["highest_frequency"] = _shared.highest_frequency

    def with_run(self, run: RunSpec) -> Mechanism:
        """This mechanism with other run settings (cam speed, step, ...), sharing its layers and tables."""
        return self.for_spec(dataclasses.replace(self.spec, run=run))

    def for_spec(self, spec: MechanismSpec) -> Mechanism:
        """This mechanism for ``spec``, a spec equal to its own but for the run settings and the title (not
        checked)."""
        return Mechanism(spec, _shared=self)

    def shared(self, key: Hashable, make: Callable[[], T]) -> T:
        """``make()``, made once for this mechanism and every one :meth:`with_run` gives, and never
        forgotten: for what depends on the mechanism alone, not on the run settings (the configuration
        tables of :mod:`vtool.solvers.model.contact`). Unlike :meth:`kept`, it is not bounded: a caller
        keeps one value per key, not one per cam speed."""
        if key not in self._lasting:
            self._lasting[key] = make()
        return self._lasting[key]

    def with_start(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, mask: int,
                   states: np.ndarray | None = None) -> Mechanism:
        """This mechanism started from a given state (full elastic coordinates, cam angle zero) in
        configuration ``mask`` instead of its static start: the next cam cycle of a run, whose state at
        the cycle's end it is (the cam is periodic in 360 deg). The cam's offset and the force scales
        stay the static start's, so the sources and tolerances are those of the first cycle. Every back
        end starts from ``start`` and the contact problem's start mask (see ContactProblem.for_run)."""
        static = self.start
        other = Mechanism(self.spec, _shared=self)
        other.__dict__["start"] = StaticStart(static.cam_offset, static.follower_force, static.follower_stiffness,
                                              np.array(q, dtype=float), np.array(qd, dtype=float),
                                              np.array(qdd, dtype=float))
        other.start_mask = int(mask)
        other.start_states = None if states is None else np.array(states, dtype=float)
        return other

    @cached_property
    def highest_frequency(self) -> float:
        """omega_max of the unconstrained system with every linear contact closed (rad/s): no
        configuration is stiffer (a Hertz contact's stiffness grows with its overlap: not counted)."""
        K = self.K.copy()
        for c in self.spec.clearances:
            if c.contact == LINEAR:
                w = np.zeros(len(K))
                w[c.ahead - 1] = 1.0  # the sense changes no stiffness (k w wᵀ)
                if 0 < c.behind <= len(K):
                    w[c.behind - 1] = -1.0
                K += c.contact_stiffness * np.outer(w, w)
        return float(undamped_modes(self.M, K).omega.max())

    @property
    def omega(self) -> float:
        """Cam speed in rad/s."""
        return self.spec.run.omega

    def layer(self, closed: frozenset[str] | set[str] | tuple[str, ...]) -> Layer:
        """The layer with these internal clearances closed (pinned ones always are)."""
        _, pinned = internal_layer_names(self.spec)
        key = frozenset(closed) | frozenset(pinned)
        key = frozenset(n for n in key if self.spec.clearance(n).ties)
        if key not in self._layers:
            self._layers[key] = build_layer(self.spec, self.M, self.K, key)
        return self._layers[key]

    def tied_layer(self, closed: frozenset[str]) -> Layer:
        """The layer with these internal clearances tied, compliant ones included: the layer whose modal
        damping a configuration with closed compliant internal contacts keeps (see
        :func:`vtool.solvers.model.configurations.partition`)."""
        _, pinned = internal_layer_names(self.spec)
        key = frozenset(n for n in frozenset(closed) | frozenset(pinned) if self.spec.clearance(n).kind == INTERNAL)
        if key not in self._layers:
            self._layers[key] = build_layer(self.spec, self.M, self.K, key)
        return self._layers[key]

    def all_layers(self) -> list[Layer]:
        """Every layer the clearances allow, rocker-open first (fewest closed first)."""
        return [self.layer(closed) for closed in possible_layers(self.spec)]

    @property
    def start_layer(self) -> Layer:
        return self.layer(frozenset(self.spec.initial.closed))

    def kept(self, key: Hashable, make: Callable[[], T]) -> T:
        """``make()``, made once for this mechanism and every one :meth:`with_run` gives (they differ in
        run settings only): ``key`` names what it depends on beyond the mechanism (the cam speed, say).
        What it returns is shared by those runs, which only read it."""
        value = self._derived.get(key)
        if value is None:
            value = make()
            if len(self._derived) >= DERIVED_KEPT:
                self._derived.clear()
            self._derived[key] = value
        return value

    @cached_property
    def start(self) -> StaticStart:
        """The static start at this cam speed (its arrays shared by the runs at this speed: every back end
        copies them before it integrates)."""
        def make() -> StaticStart:
            table = self.spec.cam.profile != "harmonic"
            start = static_start(self.spec, self.start_layer, self.omega, final=not table)
            if table:  # a lift table: start where its lift puts the cam
                from vtool.solvers.model.cam import table_start

                start = table_start(self.spec, start, self.omega, self.start_layer)
            return start

        return self.kept(("start", self.omega), make)

    @property
    def lowest_start_frequency(self) -> float:
        """The starting layer's lowest elastic natural frequency (rad/s; 0 when it has none)."""
        def make() -> float:
            omega = self.start_layer.modes.omega
            return float(omega[omega > 0].min()) if np.any(omega > 0) else 0.0

        return self.kept("lowest start frequency", make)

    @property
    def mass_and_inverse(self) -> np.ndarray:
        """[M, M⁻¹] stacked (2 x n x n)."""
        return self.kept("mass and inverse", lambda: np.stack([self.M, np.linalg.inv(self.M)]))


def assemble(spec: MechanismSpec) -> Mechanism:
    """Build the mechanism model for a spec (full matrices; layers on demand)."""
    return Mechanism(spec)
