"""The assembled mechanism: full matrices, contact layers built on demand, static start.

``assemble(spec)`` builds the full system (M, K) once. Contact layers (and
their eigenproblems and modal damping) are built the first time they are
asked for and then kept: a run builds only the layers it visits, and a
pinned clearance never produces a layer in which it is open.
"""

from __future__ import annotations

import math
from functools import cached_property

import numpy as np

from vtool.solvers.assembly import assemble_full
from vtool.solvers.initial import StaticStart, static_start
from vtool.solvers.layers import Layer, build_layer, internal_layer_names, possible_layers
from vtool.solvers.spec import INTERNAL, MechanismSpec


class Mechanism:
    """A valve train ready to solve: see the module docstring."""

    def __init__(self, spec: MechanismSpec) -> None:
        self.spec = spec
        self.M, self.K = assemble_full(spec)
        self._layers: dict[frozenset[str], Layer] = {}

    @property
    def omega(self) -> float:
        """Cam speed in rad/s."""
        return self.spec.run.rpm * math.pi / 30.0

    def layer(self, closed: frozenset[str] | set[str] | tuple[str, ...]) -> Layer:
        """The layer with these internal clearances closed (pinned ones always are)."""
        _, pinned = internal_layer_names(self.spec)
        key = frozenset(closed) | frozenset(pinned)
        key = frozenset(n for n in key if self.spec.clearance(n).kind == INTERNAL)
        if key not in self._layers:
            self._layers[key] = build_layer(self.spec, self.M, self.K, key)
        return self._layers[key]

    def all_layers(self) -> list[Layer]:
        """Every layer the clearances allow, rocker-open first (fewest closed first)."""
        return [self.layer(closed) for closed in possible_layers(self.spec)]

    @property
    def built_layers(self) -> list[Layer]:
        return list(self._layers.values())

    @property
    def start_layer(self) -> Layer:
        return self.layer(frozenset(self.spec.initial.closed))

    @cached_property
    def start(self) -> StaticStart:
        return static_start(self.spec, self.start_layer, self.omega)

    def cam_position(self, t: np.ndarray | float) -> np.ndarray | float:
        cam = self.spec.cam
        return cam.amplitude * np.sin(self.omega * np.asarray(t)) + self.start.cam_offset


def assemble(spec: MechanismSpec) -> Mechanism:
    """Build the mechanism model for a spec (full matrices; layers on demand)."""
    return Mechanism(spec)
