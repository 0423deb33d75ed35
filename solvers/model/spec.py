"""The valve-train mechanism as data: frozen specs built from a preset.

A :class:`MechanismSpec` says everything the solver needs and nothing about
how it is solved: the system coordinates, the members and how their element
coordinates map onto system coordinates (the thesis' beta matrix, Gnilka
1971 eq. 3.4, given row by row as signed coordinate numbers), the cam and
the seat (prescribed coordinates), the clearances, the modal damping per
contact layer, the static start and the run settings.

Specs are built and validated by :mod:`vtool.presets.valvetrain`; nothing
here reads files. All numbers are in the preset's unit system
(:mod:`vtool.solvers.model.units`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from vtool.solvers.model.units import UNIT_SYSTEMS, UnitSystem
from vtool.units import cam_speed

if TYPE_CHECKING:  # (a field's type only: the spring module imports numpy, which `vtool --help` must not)
    from vtool.solvers.model.friction import FrictionLaws
    from vtool.solvers.model.hla import HLAPlace
    from vtool.solvers.model.spring import SpringSpec
    from vtool.solvers.model.valveforces import ValveForces

BAR = "bar"
BEAM = "beam"
ELEMENT_SIZE = {BAR: 2, BEAM: 4}

EXTERNAL = "external"
INTERNAL = "internal"

ENABLED = "enabled"
PINNED = "pinned"
REMOVED = "removed"

#: Impact laws (see :mod:`vtool.solvers.newmark.kernel`): the thesis' local law (eq. 3.53),
#: the thesis' SCALE at internal clearances (eq. 3.54), one LCP on the consistent mass matrix.
LOCAL = "local"
THESIS = "thesis"
MOMENTUM = "momentum"
IMPACT_LAWS = (LOCAL, THESIS, MOMENTUM)

#: Contact laws of a clearance (see :mod:`vtool.solvers.model.contact`): rigid (impact laws, ties and
#: prescribed coordinates), a linear spring-dashpot acting while the parts overlap, or Hertz's
#: k delta^n with Hunt-Crossley damping (Newmark and scipy back ends).
RIGID = "rigid"
LINEAR = "linear"
HERTZ = "hertz"
CONTACT_LAWS = (RIGID, LINEAR, HERTZ)

#: Start velocities (see :mod:`vtool.solvers.model.initial`).
THESIS_START = "thesis"
QUASI_STATIC_START = "quasi-static"
START_VELOCITIES = (THESIS_START, QUASI_STATIC_START)


@dataclass(frozen=True)
class CoordinateSpec:
    """One elastic system coordinate q_i (1-based ``number``)."""

    number: int
    name: str
    motion: str  # "translation" (length) or "rotation" (rad)


@dataclass(frozen=True)
class MemberSpec:
    """One finite element: an axial bar (2 DOF) or an Euler–Bernoulli beam (4 DOF).

    ``coordinates`` maps element coordinates to system coordinates, one signed
    number per element coordinate: ``+i`` is q_i, ``-i`` is -q_i, ``0`` is a
    grounded (fixed) end. Element coordinate order follows the thesis: bar
    (u_a, u_b); beam (w_a, w_b, theta_a, theta_b).

    The section is given by ``diameter`` (solid circle) or by ``area`` (and
    ``inertia`` for beams). The mass per volume by ``specific_weight`` (divided
    by g) or ``density``. ``stiffness`` (bars: axial stiffness) and ``mass``
    (total member mass), when given, override the values from the section,
    as the valve spring needs. ``position`` and ``direction`` place the member
    in the plane for drawings and animations only (bars move along their axis,
    beams deflect at +90 degrees to it); they do not enter the dynamics.
    """

    name: str
    element: str
    length: float
    coordinates: tuple[int, ...]
    modulus: float | None = None
    diameter: float | None = None
    area: float | None = None
    inertia: float | None = None
    specific_weight: float | None = None
    density: float | None = None
    stiffness: float | None = None
    mass: float | None = None
    position: tuple[float, float] | None = None  # drawing only: end a in the plane (length units)
    direction: float = 0.0  # drawing only: axis from end a to end b, degrees from +x
    elements: int = 1  # equal elements the member is split into (see solvers.assembly.sub_elements)
    nodes: tuple[int, ...] = ()  # internal coordinates of a split member, node by node (beams: w, theta)


@dataclass(frozen=True)
class ClearanceSpec:
    """A clearance between two coordinates.

    The gap is ``q[ahead] - q[behind]``: positive while open, contact when it
    reaches zero. ``kind`` is ``external`` when ``behind`` is a prescribed
    coordinate (cam, seat) and ``internal`` between two elastic coordinates,
    where the contact force acts equal and opposite on the pair. ``state``:
    ``enabled`` (opens and closes), ``pinned`` (always closed: the pair is one
    coordinate) or ``removed`` (never closes, not monitored).

    ``contact``: ``rigid`` (a closed clearance ties its pair or prescribes its
    ahead coordinate; closing is an impact) or ``linear`` (while the parts
    overlap, δ = -gap > 0, a spring ``contact_stiffness`` k and a dashpot c act
    between them: F = k δ + c δ̇; piecewise linear, so every back end applies).
    The dashpot is ``contact_damping`` c, or ``contact_damping_ratio`` ζ with
    c = 2 ζ √(k m), m the diagonal mass of the ahead coordinate (internal:
    the two diagonal masses in series), the masses the local impact law uses.
    A linear contact acts while the parts overlap (Kelvin–Voigt): near the
    end of a contact its dashpot may pull (F < 0), a known property of the
    model; the overlap, not the force, decides when the contact ends.
    ``hertz``: F = k δⁿ (1 + a δ̇/v⁻), n = ``contact_exponent``, with
    Hunt–Crossley damping at the approach velocity v⁻ of the contact's
    closing; it never pulls. ``restitution`` is the rebound of a lone mass:
    a is the root of a (1 + e) = ln((1 + a)/(1 - a e)), exact for any n
    (:mod:`vtool.solvers.model.hertz`; Hunt and Crossley's 3(1 - e)/2 is its
    expansion near e = 1), and a Hertz contact takes 0.01 <= e <= 1 (e = 0
    would need infinite damping). Nonlinear: the Newmark back end iterates,
    scipy integrates it, exact refuses it.

    ``opening`` (length, default 0) and ``sense`` (+1 or -1, default +1) make
    the gap ``sense (q[ahead] - q[behind]) + opening``: a clearance that is
    open by ``opening`` when its pair sits where the model's coordinates are
    zero (a pitch segment's coil gap: :mod:`vtool.solvers.model.spring`).
    ``behind = 0`` is the ground (the frame, q ≡ 0; kind ``external``).
    Only a compliant contact takes a nonzero opening, sense -1 or the ground
    (its spring then carries a constant force term k·opening; a rigid one
    would need an affine tie). With the defaults the gap is exactly
    q[ahead] - q[behind], as before.
    """

    name: str
    ahead: int
    behind: int
    kind: str
    state: str = ENABLED
    restitution: float = 0.0
    impact: str | None = None  # impact law; None: the mechanism's default (ContactSpec.impact)
    contact: str = RIGID
    contact_stiffness: float = 0.0  # force/length
    contact_damping: float | None = None  # force*time/length
    contact_damping_ratio: float | None = None  # of critical, on the local masses
    contact_exponent: float = 1.5  # hertz
    opening: float = 0.0  # length: the gap where q[ahead] = q[behind] (compliant contacts)
    sense: int = 1  # +1: gap = q[ahead] - q[behind] + opening; -1: q[behind] - q[ahead] + opening

    @property
    def offset(self) -> bool:
        """The gap is not plainly q[ahead] - q[behind]: an opening, sense -1 or the ground behind."""
        return self.opening != 0.0 or self.sense != 1 or self.behind == 0

    def gap(self, q_ahead: float, q_behind: float) -> float:
        """The gap at these positions of its pair (``q_behind`` = 0 for the ground)."""
        return self.sense * (q_ahead - q_behind) + self.opening

    @property
    def rigid(self) -> bool:
        return self.contact == RIGID

    @property
    def ties(self) -> bool:
        """A closed rigid internal clearance: its pair is one coordinate of the layer."""
        return self.kind == INTERNAL and self.contact == RIGID


@dataclass(frozen=True)
class CamSpec:
    """The cam: q_cam = base + L(omega t) (see :mod:`vtool.solvers.model.cam`).

    ``profile = "harmonic"``: the thesis' cam, L = A + A sin(omega t), A =
    ``amplitude``. ``profile = "table"``: a lift table (``angles`` in deg from
    the preset's angle zero, ``lifts`` in length units) fitted by a Fourier
    series of ``harmonics`` terms, or of the fewest terms that meet
    ``tolerance`` (length); ``lift_table`` is the CSV file it was read from,
    as written in the preset. ``amplitude`` of a table cam is half its lift.
    ``offset = None`` applies the thesis' static-start rule (XZERO, see
    :mod:`vtool.solvers.model.initial`).
    """

    coordinate: int
    amplitude: float
    offset: float | None = None
    name: str = "cam"
    profile: str = "harmonic"
    angles: tuple[float, ...] = ()
    lifts: tuple[float, ...] = ()
    harmonics: int | None = None
    tolerance: float | None = None
    lift_table: str | None = field(default=None, compare=False)  # provenance only


@dataclass(frozen=True)
class SeatSpec:
    """A fixed seat: q_seat = position (thesis CLEAR)."""

    coordinate: int
    position: float
    name: str = "seat"
    lash: float | None = None  # when the preset gave the lash, position was computed from it


@dataclass(frozen=True)
class InitialSpec:
    """The static start at omega t = 0 (thesis INITAL).

    ``closed`` names the clearances in contact at the start (thesis:
    configuration VII, cam and rocker). ``spring_preload`` is the valve-spring
    force with the cam on its base circle, ``lever_ratio`` the follower force
    per unit spring force (the rocker arm ratio).
    """

    closed: tuple[str, ...]
    spring_preload: float
    lever_ratio: float
    velocities: str = THESIS_START


@dataclass(frozen=True)
class ContactSpec:
    """The impact law every clearance uses unless it names its own, and the thesis' SCALE.

    ``rocker_scale`` is SCALE of Gnilka eq. 3.54 (the ``thesis`` law at an
    internal clearance: the tied pair takes SCALE times the ahead coordinate's
    velocity; the thesis chose it "from 1.0 to 2.0").
    """

    impact: str = LOCAL
    rocker_scale: float = 1.0


@dataclass(frozen=True)
class LayerDampingSpec:
    """Modal damping ratios of one contact layer.

    A layer is named by the internal clearances closed in it. ``mode_ratios``
    overrides the ratio of single modes, numbered 1, 2, ... in ascending
    natural frequency (rigid-body modes included, and always undamped).
    """

    closed: tuple[str, ...]
    default_ratio: float
    mode_ratios: tuple[tuple[int, float], ...] = ()


@dataclass(frozen=True)
class DampingSpec:
    """Modal damping (thesis section III.C) and the global factor (thesis COFD)."""

    factor: float = 1.0
    default_ratio: float = 0.1
    layers: tuple[LayerDampingSpec, ...] = ()

    def for_layer(self, closed: frozenset[str]) -> LayerDampingSpec:
        for layer in self.layers:
            if frozenset(layer.closed) == closed:
                return layer
        return LayerDampingSpec(tuple(sorted(closed)), self.default_ratio)


#: Newmark's parameters as a run may set them: 0 < beta <= 1/2, 1/2 <= gamma <= 1 (the one statement of the
#: rule: the preset loader reads them with these bounds, the Newmark back end's check refuses the same).
BETA_RANGE = (0.0, 0.5)  # (exclusive, inclusive)
GAMMA_RANGE = (0.5, 1.0)  # (inclusive, inclusive)

#: The back end a run uses when its settings name none (the registry's default,
#: :data:`vtool.solvers.backends.DEFAULT`; the one place outside the registry a back end is named).
DEFAULT_BACKEND = "newmark"


@dataclass(frozen=True)
class RunSpec:
    """Run settings: cam speed, length of run, time step, back end, output."""

    rpm: float
    degrees: float
    time_step: float
    backend: str = DEFAULT_BACKEND
    output_interval: float = 1.0  # degrees of cam rotation between output rows
    beta: float = 1.0 / 6.0
    gamma: float = 0.5
    quantities: tuple[str, ...] = ()  # extra CSV/plot columns: "q7", "q1-q9", "F2"
    # cycle by cycle (vtool.solvers.studies.steady): a fixed number of cam cycles (0: run ``degrees``), or
    # until the cycle's start state and metrics change by less than steady_tolerance (0: off), at most
    # steady_max_cycles; ``degrees`` is then unused
    cycles: int = 0
    steady_tolerance: float = 0.0
    steady_max_cycles: int = 0
    # speed criteria (vtool.solvers.studies.metrics): the follower leaves the cam when the cam contact is
    # open during the lift event for more than jump_angle (deg) with a gap above jump_gap (length); the
    # valve bounces when it re-opens after seating by more than bounce_lift (length); None: the default
    # share of the cam's lift (metrics.GAP_FRACTION)
    jump_angle: float = 1.0
    jump_gap: float | None = None
    bounce_lift: float | None = None
    # quantities whose cam-order amplitudes (orders 1..highest_order over the evaluated cycles) are metrics
    orders: tuple[str, ...] = ()
    highest_order: int = 24

    @property
    def omega(self) -> float:
        """Cam speed in rad/s (:func:`vtool.units.cam_speed`)."""
        return cam_speed(self.rpm)


#: Follower kinds and arrangements (see :mod:`vtool.solvers.model.camshape`).
FLAT = "flat"
ROLLER = "roller"
FOLLOWER_KINDS = (FLAT, ROLLER)
TRANSLATING = "translating"
FINGER = "finger"
ROCKER = "rocker"
ARRANGEMENTS = (TRANSLATING, FINGER, ROCKER)
LEVERS = (FINGER, ROCKER)  # arrangements with a FingerSpec: end pivot, centre pivot


@dataclass(frozen=True)
class FingerSpec:
    """An end-pivot (type II) finger follower's geometry, at the base circle.

    In the finger's plane, x along the finger from its pivot (the lash
    adjuster's ball: :class:`MechanismSpec` keeps it a named coordinate), y
    downwards (the valve's opening direction). The roller centre is at
    (``roller_arm``, -``roller_height``), the valve pad's centre at
    (``valve_arm``, 0); the valve axis is vertical through the pad; the cam
    centre is above the roller, ``cam_offset`` further along x than the roller
    centre. The cam turns so that its surface at the roller runs from the
    valve end towards the pivot (positive sense of this y-down frame).

    A centre-pivot rocker (arrangement ``rocker``) has the same parameters
    with the roller on the other side of the pivot, at (-``roller_arm``,
    ``roller_height``) (the rocker's line through the pivot and the pad),
    and the cam below it: the cam lifts the roller and the valve arm opens
    the valve.
    """

    roller_arm: float
    valve_arm: float
    roller_height: float = 0.0
    cam_offset: float = 0.0


@dataclass(frozen=True)
class OilSpec:
    """The oil at the cam contact: dynamic viscosity (Pa s) and pressure-viscosity coefficient (1/Pa)."""

    viscosity: float
    pressure_viscosity: float


@dataclass(frozen=True)
class FollowerSpec:
    """The cam's follower: its geometry gives the cam's shape and the contact stress.

    ``kind``: ``flat`` (a flat face, ``face_diameter`` wide) or ``roller``
    (``roller_radius``). ``arrangement``: ``translating`` (the follower moves
    along a line through the cam centre: bucket, tappet, roller lifter) or
    ``finger`` (end pivot) or ``rocker`` (centre pivot) (:class:`FingerSpec`,
    roller only). ``base_radius`` is the cam's
    base-circle radius (profile, not pitch curve), ``width`` the contact
    length of the line contact. ``lift`` is the lift law at the cam when it
    is not the model's cam (a finger follower's: the model's cam coordinate
    then moves as the geometric valve lift over the finger's nominal ratio,
    see :func:`vtool.solvers.model.camshape.model_lift`). Moduli in the
    preset's pressure unit.
    """

    kind: str
    arrangement: str
    base_radius: float
    width: float
    roller_radius: float = 0.0
    face_diameter: float | None = None
    cam_modulus: float = 0.0
    cam_poisson: float = 0.3
    follower_modulus: float = 0.0
    follower_poisson: float = 0.3
    finger: FingerSpec | None = None
    lift: CamSpec | None = None
    oil: OilSpec | None = None
    #: cam-follower friction coefficient (flat face: Coulomb sliding; roller: rolling traction, the bearing's
    #: drag referred to the rim), see :mod:`vtool.solvers.studies.torque`
    friction: float = 0.0
    #: valve-guide Coulomb friction force (the stem's side load times its coefficient, taken as constant) and
    #: its regularisation velocity v_r (F = F_g tanh(v / v_r)); 0: none (:mod:`vtool.solvers.studies.torque`)
    guide_friction: float = 0.0
    guide_velocity: float = 1.0
    #: the sliding law (Coulomb or Stribeck), pivot friction and roller slip (None: Coulomb, neither);
    #: :class:`vtool.solvers.model.friction.FrictionLaws`
    laws: FrictionLaws | None = None


@dataclass(frozen=True)
class CheckLimit:
    """One limit of a preset's [checks] table (see :mod:`vtool.solvers.studies.checks`)."""

    name: str
    limit: float


@dataclass(frozen=True)
class MechanismSpec:
    """A whole valve-train study: mechanism, clearances, damping, start and run."""

    title: str
    units: str
    gravity: float
    coordinates: tuple[CoordinateSpec, ...]
    members: tuple[MemberSpec, ...]
    cam: CamSpec
    seat: SeatSpec | None
    clearances: tuple[ClearanceSpec, ...]
    initial: InitialSpec
    damping: DampingSpec
    run: RunSpec
    notes: str = ""
    contact: ContactSpec = field(default_factory=ContactSpec)
    follower: FollowerSpec | None = None  # cam shape and contact stress (presets' [follower] table)
    checks: tuple[CheckLimit, ...] = ()  # limits signed off (presets' [checks] table)
    #: valve springs' data sheets (presets' [[springs]]; a train's data-sheet spring): stress, fatigue, coil bind
    springs: tuple[SpringSpec, ...] = ()
    #: JSON text of the preset's [train] table when it was entered by train type (provenance: a saved copy
    #: keeps the type's parameters while the model is still what they expand to; see presets/trains.py)
    train: str = field(default="", compare=False)
    #: a hydraulic lash adjuster in a bar member's place ([hla]; a nonlinear element, solvers/model/hla.py)
    hla: HLAPlace | None = None
    #: forces on the valve: guide friction, gas force ([valve_forces]; solvers/model/valveforces.py)
    valve_forces: ValveForces | None = None
    kind: str = field(default="valvetrain", init=False)

    @property
    def lift_law(self) -> CamSpec:
        """The lift law at the cam: the follower's own when it has one, else the model's cam."""
        if self.follower is not None and self.follower.lift is not None:
            return self.follower.lift
        return self.cam

    def impact_law(self, clearance: ClearanceSpec) -> str:
        """The impact law of a clearance: its own, or the mechanism's default."""
        return clearance.impact or self.contact.impact

    @property
    def unit_system(self) -> UnitSystem:
        return UNIT_SYSTEMS[self.units]

    @property
    def n_coordinates(self) -> int:
        return len(self.coordinates)

    def force_label(self, index: int) -> str:
        """``F`` and clearance ``index``'s ahead coordinate; a second clearance on the same coordinate (a
        spring's top coil contact on the retainer beside another contact) gets ``_2`` (``_3``, ...), so that
        CSV headers and metric names stay unique."""
        ahead = self.clearances[index].ahead
        repeat = sum(c.ahead == ahead for c in self.clearances[:index])
        return f"F{ahead}" + (f"_{repeat + 1}" if repeat else "")

    def clearance(self, name: str) -> ClearanceSpec:
        for c in self.clearances:
            if c.name == name:
                return c
        raise KeyError(name)
