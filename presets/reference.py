"""The preset reference (docs/presets.md), made from the loaders' own reads.

Every key's type, unit, allowed values and default come from the read that
the loader makes (:class:`vtool.presets.fields.Table`, noted inside
:func:`vtool.presets.fields.recording`) while it loads each shipped preset
and the :data:`VARIANTS` below (shipped presets with a switch turned, so
that the keys of other branches are read too: a lift-table cam, a Hertz
contact, a single boom pulse, user criteria). What a key means is the one
thing written by hand: :data:`MEANINGS`, per kind, by the key's path
(``members.*.length``: any member; ``clearances[].gap``: any entry). A key
the loader reads without a meaning here, or a meaning for a key it never
reads, fails ``tests/test_presets_reference.py``.

``python benchmarks/presets_reference.py --write`` regenerates
docs/presets.md; ``--check`` says whether it is current.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from vtool.presets import list_presets, load_document, read_document
from vtool.presets.fields import REQUIRED, FieldRead, recording
from vtool.presets.kinds import KINDS
from vtool.presets.paths import set_fields
from vtool.solvers import backends

#: Shipped presets with fields changed (None: removed) so that the loader reads the keys of its other branches.
VARIANTS: tuple[tuple[str, dict[str, Any]], ...] = (
    ("gnilka-1a", {"run.cycles": 2, "run.jump_gap": 0.001, "run.bounce_lift": 0.001}),
    ("gnilka-1a", {"run.steady": {"tolerance": 1e-3, "max_cycles": 5}}),
    # the other unit system of each kind (the same numbers: each key's unit and SI-derived bounds in it)
    ("gnilka-1a", {"units": "SI"}), ("boom-brick-wall", {"units": "m-N-s"}),
    ("boom-tall-building", {"units": "m-N-s", "floors[0].moment_of_inertia": 4e-4, "floors[0].storey_height": 3.7,
                            "floors[0].face_width": 30.0}),
    ("plate-table2", {"units": "SI", "plate.density": 7800.0, "plate.youngs_modulus": 2e11}),
    ("gnilka-1a", {"seat.lash": 0.01, "seat.position": None, "clearances[0].contact": "linear", "clearances[0].contact_stiffness": 1e6,
                   "clearances[0].contact_damping_ratio": 0.05, "clearances[0].impact": "momentum"}),
    ("gnilka-1a", {"clearances[0].contact": "linear", "clearances[0].contact_stiffness": 1e6,
                   "clearances[0].contact_damping": 1.0}),
    # a measured scan: its units, angle, valve lift and smoothing (presets/cam_scan.py)
    ("ramped-cam", {"cam.scan": {"lift_unit": "in", "angle": "cam", "lift_of": "valve", "rocker_ratio": 1.0,
                                 "smoothing": "fourier", "noise": 1e-5, "peak_tolerance": 1e-3}}),
    ("gnilka-1a", {"clearances[2].contact": "hertz", "clearances[2].contact_stiffness": 1e7,
                   "clearances[2].contact_exponent": 1.5, "clearances[2].restitution": 0.5}),
    ("gnilka-1a", {"run.steady": {"tolerance": 1e-3, "max_cycles": 20}, "run.jump_gap": 0.002,
                   "run.bounce_lift": 0.002, "run.orders": ["F7"]}),
    ("gnilka-1a", {"run.cycles": 3}),
    # the friction laws (presets/friction.py): Stribeck on a flat face and the guide; a finger's pivot and slip
    ("direct-acting-bucket", {"train.follower.friction_law": "stribeck", "train.follower.guide_friction": 5.0}),
    ("ohc-finger-follower", {"train.follower.friction_law": "stribeck", "train.follower.pivot_friction": 0.1,
                             "train.follower.pivot_radius": 4.0, "train.follower.slip_friction": 0.1,
                             "train.follower.roller_inertia": 4e-4}),
    # a data-sheet spring's other branches: R_m = A / d^m, elliptic wire, coil contact settings (presets/springs.py)
    ("nested-spring-clash", {"train.spring.tensile_strength": {"A": 2300.0, "m": 0.1}, "train.spring.wire_height": 3.8,
                             "train.spring.block_stiffness": 1e4, "train.spring.block_damping_ratio": 0.2,
                             "train.spring.inner.tensile_strength": {"A": 2300.0, "m": 0.1},
                             "train.spring.inner.wire_height": 2.8, "train.spring.inner.coil_contact": "none"}),
    # forces on the valve's motion (presets/valveforces.py): Stribeck guide friction and a cylinder-pressure table
    ("direct-acting-bucket", {"run.backend": backends.with_flag("nonlinear_elements")[0], "valve_forces": {
        "guide_friction": 15.0, "guide_velocity": 20.0, "static_friction": 25.0, "stribeck_velocity": 100.0,
        "viscous": 0.002, "gas_crank_angles": [0.0, 360.0], "gas_pressures": [0.1, 2.0], "head_diameter": 30.0,
        "seat_side": "cylinder", "gas_phase": 0.0}}),
    *((name, changes) for name in ("boom-brick-wall", "boom-tall-building") for changes in (
        {"boom.pulse": "N", "boom.envelope": None},
        {"boom.pulse": "csv", "boom.csv": "pulse.csv", "boom.envelope": None},
        {"boom.envelope": {"types": ["N"], "s": [1.6, 2.2, 0.1], "r1": [0.0, 0.5, 0.1], "family": "thesis"}},
        {"criteria": ["own"], "criterion": [{"name": "own", "source": "a reference", "response": "velocity",
                                             "value": 1.0, "unit": "in/s", "f_min": 1.0, "f_max": 50.0}]})),
)

#: The friction-law keys of a [follower] (presets/friction.py; the laws: solvers/model/friction.py).
FRICTION_LAWS = {
    "follower.friction_law": "Law of the sliding contacts (flat face, valve guide): Coulomb or Stribeck.",
    "follower.static_friction": "Stribeck: the cam contact's coefficient at rest, mu_s (friction is mu_c).",
    "follower.guide_static_friction": "Stribeck: the valve guide's friction force at rest.",
    "follower.stribeck_velocity": "Stribeck: the speed v_S over which mu falls from mu_s to mu_c.",
    "follower.viscous_friction": "Stribeck: the cam contact's coefficient rise per sliding speed, k_v.",
    "follower.pivot_friction": "Friction coefficient of a finger's or rocker's pivot: T = mu F_pivot r_p.",
    "follower.pivot_radius": "Radius r_p of the pivot's pin or ball.",
    "follower.pivot_velocity": "Angular velocity below which the pivot friction is regularised (tanh).",
    "follower.slip_friction": "A roller's traction limit mu_slip: above mu_slip F_n it slips on the cam.",
    "follower.roller_inertia": "The roller's moment of inertia about its pin (its slip).",
}

#: Keys every kind has.
COMMON = {
    "kind": "Which study the preset describes; picks its loader, runner and TUI screen (presets/kinds.py).",
    "title": "One line naming the study; shown in summaries, reports and the TUI.",
    "notes": "Free text kept with the preset (sources, choices made).",
    "units": "The unit system every number of the preset is in; every output names its units.",
}

BOOM = {
    "criteria": "Names of the criteria to assess: built-in ones or those of [[criterion]] tables.",
    "criterion": "User criteria: a peak response (velocity or displacement) not to exceed.",
    "criterion[].name": "The criterion's name, as listed in `criteria`.",
    "criterion[].source": "Where the limit comes from (a standard, a paper), printed with the results.",
    "criterion[].response": "The response the limit is on.",
    "criterion[].value": "The limit, in `unit`.",
    "criterion[].unit": "The unit of `value`.",
    "criterion[].tentative": "Marks the results of this criterion as tentative.",
    "criterion[].f_min": "Lowest structure frequency the criterion applies to.",
    "criterion[].f_max": "Highest structure frequency the criterion applies to.",
    "boom": "The boom loading: pulse shape, durations and damping.",
    "boom.positive_durations": "Durations of the pulse's positive phase (tau) to assess.",
    "boom.pulse": "The pulse: one of the thesis' shapes N, P, Q, R, T, the envelope over a family of "
                  "shapes, or a tabulated pulse from a CSV file.",
    "boom.damping": "Damping ratio of the structure's oscillator (0: undamped, as the thesis).",
    "boom.s": "Shape parameter s of a single pulse (thesis notation).",
    "boom.r1": "Rise-time ratio r1 of a single pulse.",
    "boom.r2": "Second ratio r2 of a single pulse (shapes that have one).",
    "boom.alpha": "Parameter alpha of a single pulse (shapes that have one).",
    "boom.beta": "Parameter beta of a single pulse (shapes that have one).",
    "boom.csv": "CSV file of a tabulated pulse (time, pressure), found beside the preset.",
    "boom.envelope": "The family of pulses whose envelope is assessed (default: the thesis' ranges).",
    "boom.envelope.types": "Pulse shapes in the envelope.",
    "boom.envelope.s": "Range of s: first, last, step.",
    "boom.envelope.r1": "Range of r1: first, last, step.",
    "boom.envelope.alpha": "Parameter alpha of the envelope's shapes.",
    "boom.envelope.beta": "Parameter beta of the envelope's shapes.",
    "boom.envelope.family": "How the family is built: the thesis' or with equal rise times.",
    "design": "The frequency range of the design curves.",
    "design.f_min": "Lowest frequency of the design curves.",
    "design.f_max": "Highest frequency of the design curves.",
    "design.points": "Points of each design curve.",
}

MEANINGS: dict[str, dict[str, str]] = {
    "valvetrain": COMMON | {
        "gravity": "Standard gravity that turns a specific weight into a density.",
        "coordinates": "The elastic system's coordinates q1, q2, ... in order (thesis Fig. 2.5).",
        "coordinates[].name": "What the coordinate is (shown in tables and the TUI).",
        "coordinates[].motion": "Whether the coordinate is a displacement or a rotation (its unit).",
        "cam": "The prescribed cam motion.",
        "cam.coordinate": "The number of the cam's prescribed coordinate (after the elastic ones).",
        "cam.name": "The cam's name in tables and events.",
        "cam.profile": "Harmonic (q_cam = amplitude sin(omega t) + offset, the thesis' cam) or a lift table.",
        "cam.amplitude": "Amplitude of the harmonic cam's motion.",
        "cam.offset": "Where the cam starts: \"static-start\" (the thesis' XZERO rule) or a length.",
        "cam.lift_table": "CSV file of lift against cam angle (table profile), found beside the preset.",
        "cam.polyline": "A measured scan as a polyline script of angle,lift points (instead of lift_table), "
                        "found beside the preset (presets/cam_scan.py).",
        "cam.scan": "What a measured lift table's numbers are, and its smoothing (presets/cam_scan.py).",
        "cam.scan.lift_unit": "The unit of the scan's lifts (mm, in, thou, m); converted to the preset's.",
        "cam.scan.angle": "Cam degrees, or crank degrees (halved to cam degrees: four-stroke).",
        "cam.scan.lift_of": "Tappet (cam follower) lift, or valve lift (divided by rocker_ratio).",
        "cam.scan.rocker_ratio": "Valve lift per tappet lift, for a valve-lift scan.",
        "cam.scan.smoothing": "none; fourier: a truncated Fourier series cut off at the scan's noise (equal steps "
                              "dividing 360); spline: a smoothing spline whose residual is the noise (any steps).",
        "cam.scan.noise": "The scan's noise rms (default: estimated from its spectrum).",
        "cam.scan.peak_tolerance": "How far smoothing may move the peak lift (default: 4 x the noise rms).",
        "cam.harmonics": "Harmonics of the lift table's Fourier fit (0: as many as the table needs).",
        "cam.tolerance": "Largest lift error the fit may leave.",
        "seat": "The valve seat: a prescribed, fixed coordinate (absent: no seat).",
        "seat.coordinate": "The number of the seat's prescribed coordinate.",
        "seat.name": "The seat's name in tables and events.",
        "seat.position": "The seat's position on its coordinate.",
        "cam.angles": "Cam angles of an inline lift table (a saved copy's, or an expanded train's).",
        "cam.lifts": "Lifts of an inline lift table, one per angle.",
        # [follower] and [checks] (presets/follower.py): the cam's shape and contact stress, limits
        "follower": "The cam's follower: its geometry gives the cam's shape and the contact stress.",
        "follower.kind": "A flat face or a roller.",
        "follower.friction": "Friction coefficient of the cam-follower contact (its share of the drive torque).",
        "hla": "A hydraulic lash adjuster in a bar member's place (solvers/model/hla.py; a nonlinear element: scipy back end).",
        "hla.member": "The stiffness-given bar member it sits in (its linear stiffness stays; the element adds the rest).",
        "hla.sense": "What the member's positive elongation is for the adjuster: compression (it shortens) or extension.",
        "hla.plunger_diameter": "The plunger's diameter d (area A = pi d^2/4).",
        "hla.chamber_volume": "The high-pressure chamber's oil volume V0 at zero plunger extension.",
        "hla.spring_rate": "The plunger spring's rate (it pushes the plunger out).",
        "hla.spring_preload": "The plunger spring's force at zero extension.",
        "hla.gap": "Radial clearance h of the plunger in its bore (leakage Q = pi d h^3 dp / (12 mu L)).",
        "hla.gap_length": "Sealing length L of the plunger's gap.",
        "hla.viscosity": "The oil's dynamic viscosity mu in the gap.",
        "hla.supply_pressure": "The oil gallery's (gauge) pressure behind the check valve.",
        "hla.check_conductance": "The open ball check valve's flow per pressure difference above crack_pressure.",
        "hla.crack_pressure": "Pressure difference at which the check valve opens.",
        "hla.bulk_pressures": "Gauge pressures of the oil's bulk-modulus table (increasing).",
        "hla.bulk_moduli": "The oil's bulk modulus at bulk_pressures (linear between, constant beyond).",
        "hla.air_fraction": "Entrained air by volume at atmospheric pressure (isothermal, Wood's mixture rule).",
        "hla.damping": "Viscous damping of the plunger in its bore.",
        "hla.initial_pressure": "Chamber pressure at the start (default: the static load's, at least the supply pressure).",
        "valve_forces": "Forces acting on the valve's motion: guide friction and the gas force (presets/valveforces.py; scipy back end).",
        "valve_forces.coordinate": "The coordinate they act on (default: the valve, the seat clearance's ahead coordinate).",
        "valve_forces.guide_friction": "Coulomb guide friction F_c in F = [F_c + (F_s - F_c) exp(-(v/v_s)^2)] tanh(v/v_r) + c_v v.",
        "valve_forces.guide_velocity": "Regularisation velocity v_r of the friction's sign (tanh).",
        "valve_forces.static_friction": "Stribeck static peak F_s (>= F_c; default F_c: no Stribeck dip).",
        "valve_forces.stribeck_velocity": "Stribeck velocity v_s (required with static_friction).",
        "valve_forces.viscous": "Viscous guide friction coefficient c_v.",
        "valve_forces.gas_crank_angles": "Crank angles of the cylinder-pressure table (increasing, within one 720-degree cycle; periodic).",
        "valve_forces.gas_pressures": "Cylinder (gauge) pressure at gas_crank_angles (linear between).",
        "valve_forces.head_diameter": "Valve head diameter: the gas force is the pressure on pi D^2/4.",
        "valve_forces.seat_side": "cylinder: the pressure presses the valve onto its seat (a poppet valve); port: away from it.",
        "valve_forces.gas_phase": "Crank angle at cam angle zero (crank = 2 cam + phase).",
        "follower.guide_friction": "Valve-guide Coulomb friction force (stem side load times its coefficient).",
        "follower.guide_velocity": "Regularisation velocity of the guide friction: F = F_g tanh(v / v_r).",
        **FRICTION_LAWS,
        "follower.arrangement": "Translating (bucket, tappet, roller lifter) or an end-pivot finger.",
        "follower.base_radius": "The cam's base-circle radius (profile).",
        "follower.width": "Length of the line contact (roller or lobe width).",
        "follower.roller_radius": "The roller's radius.",
        "follower.face_diameter": "Diameter of the flat face (the contact's travel limit).",
        "follower.cam_modulus": "Young's modulus of the cam (Hertz contact).",
        "follower.cam_poisson": "Poisson's ratio of the cam.",
        "follower.follower_modulus": "Young's modulus of the follower.",
        "follower.follower_poisson": "Poisson's ratio of the follower.",
        "follower.roller_arm": "Finger: pivot to roller centre, along the finger.",
        "follower.valve_arm": "Finger: pivot to the valve pad's centre.",
        "follower.roller_height": "Finger: roller centre above the pivot-pad line.",
        "follower.cam_offset": "Finger: cam centre beyond the roller centre, along the finger.",
        "follower.lift": "The lift law at the cam when it is not [cam] (a finger's): [cam]'s keys.",
        "follower.lift.profile": "Harmonic or a lift table.",
        "follower.lift.lift_table": "CSV file of the law's lift against cam angle.",
        "follower.lift.polyline": "A measured lift law as a polyline script of angle,lift points (as cam.polyline).",
        "follower.lift.scan": "What a measured lift law's numbers are, and its smoothing (as cam.scan).",
        "follower.lift.angles": "Cam angles of the law's table.",
        "follower.lift.lifts": "Lifts of the law's table.",
        "follower.lift.harmonics": "Harmonics of the law's Fourier fit.",
        "follower.lift.tolerance": "Largest lift error the law's fit may leave.",
        "follower.oil": "The oil at the cam contact (film thickness by Dowson-Higginson).",
        "follower.oil.viscosity": "Dynamic viscosity at the contact's inlet.",
        "follower.oil.pressure_viscosity": "Pressure-viscosity coefficient alpha.",
        "checks": "Limits signed off; the summary says pass or fail with the margin.",
        "checks.contact_pressure_max": "Largest Hertz pressure at the cam contact.",
        "checks.cam_radius_min": "Smallest convex radius of curvature of the cam (negative: undercut).",
        "checks.contact_travel_max": "Largest contact offset on a flat face.",
        "checks.pressure_angle_max": "Largest pressure angle.",
        "checks.seating_velocity_max": "Largest valve seating velocity.",
        # [train] (presets/trains.py, presets/springs.py): a valve train by type and parts
        "train": "The valve train by type and parts, expanded to the explicit model (`vtool presets expand`).",
        "train.type": "The train's layout: OHV pushrod, direct-acting bucket or end-pivot roller finger.",
        "train.pushrod": "The pushrod (a bar).",
        "train.pushrod.length": "The pushrod's length.",
        "train.pushrod.diameter": "The pushrod's diameter.",
        "train.pushrod.modulus": "The pushrod's Young's modulus.",
        "train.pushrod.specific_weight": "The pushrod's weight per volume.",
        "train.rocker": "The rocker (two beams about its pivot).",
        "train.rocker.cam_arm": "Pivot to the pushrod end.",
        "train.rocker.valve_arm": "Pivot to the valve end.",
        "train.rocker.diameter": "The rocker's section diameter.",
        "train.rocker.modulus": "The rocker's Young's modulus.",
        "train.rocker.specific_weight": "The rocker's weight per volume.",
        "train.valve": "The valve (a bar from its tip to its head).",
        "train.valve.length": "The valve's length.",
        "train.valve.diameter": "The valve stem's diameter.",
        "train.valve.modulus": "The valve's Young's modulus.",
        "train.valve.specific_weight": "The valve's weight per volume.",
        "train.valve.mass": "The valve's mass (instead of one from its section).",
        "train.bucket": "The bucket tappet (a bar between the cam contact and the valve tip).",
        "train.bucket.mass": "The bucket's mass with shim, retainer and keepers.",
        "train.bucket.stiffness": "Axial stiffness of crown, shim and stem tip in series.",
        "train.bucket.length": "The bucket's length (drawings).",
        "train.finger": "The finger follower (two beams: pivot to roller, roller to pad).",
        "train.finger.roller_arm": "Pivot to roller centre, along the finger.",
        "train.finger.valve_arm": "Pivot to the valve pad's centre.",
        "train.finger.roller_height": "Roller centre above the pivot-pad line.",
        "train.finger.cam_offset": "Cam centre beyond the roller centre, along the finger.",
        "train.finger.area": "The finger's section area.",
        "train.finger.inertia": "The finger's section second moment of area.",
        "train.finger.modulus": "The finger's Young's modulus.",
        "train.finger.density": "The finger's mass per volume (with its roller).",
        "train.hla": "A hydraulic lash adjuster under the finger's pivot (solvers/model/hla.py; scipy back end).",
        "train.hla.plunger_mass": "The plunger's moving mass (with the pivot ball).",
        "train.hla.plunger_diameter": "The plunger's diameter d (area A = pi d^2/4).",
        "train.hla.chamber_volume": "The high-pressure chamber's oil volume V0 at zero plunger extension.",
        "train.hla.spring_rate": "The plunger spring's rate (it pushes the plunger out).",
        "train.hla.spring_preload": "The plunger spring's force at zero extension.",
        "train.hla.gap": "Radial clearance h of the plunger in its bore (leakage Q = pi d h^3 dp / (12 mu L)).",
        "train.hla.gap_length": "Sealing length L of the plunger's gap.",
        "train.hla.viscosity": "The oil's dynamic viscosity mu in the gap.",
        "train.hla.supply_pressure": "The oil gallery's (gauge) pressure behind the check valve.",
        "train.hla.check_conductance": "The open ball check valve's flow per pressure difference above crack_pressure.",
        "train.hla.crack_pressure": "Pressure difference at which the check valve opens.",
        "train.hla.bulk_pressures": "Gauge pressures of the oil's bulk-modulus table (increasing).",
        "train.hla.bulk_moduli": "The oil's bulk modulus at bulk_pressures (linear between, constant beyond).",
        "train.hla.air_fraction": "Entrained air by volume at atmospheric pressure (isothermal, Wood's mixture rule).",
        "train.hla.damping": "Viscous damping of the plunger in its bore.",
        "train.hla.initial_pressure": "Chamber pressure at the start (default: the static load's, at least the supply pressure).",
        "train.pivot": "The support under the finger's pivot (where a lash adjuster sits).",
        "train.pivot.mass": "The moving mass at the pivot.",
        "train.pivot.stiffness": "The pivot support's stiffness.",
        "train.pivot.length": "The pivot member's length (drawings).",
        "train.spring": "The valve spring (presets/springs.py).",
        "train.spring.rate": "The spring's rate.",
        "train.spring.mass": "The spring's own mass.",
        "train.spring.preload": "Force at the installed length (valve closed).",
        "train.spring.installed_length": "Installed length (with free_length: the preload).",
        "train.spring.free_length": "Free length (with installed_length: the preload).",
        "train.spring.length": "The spring member's length (drawings; default the installed length).",
        "train.spring.elements": "Equal bar elements of the spring (surge modes).",
        "train.spring.wire_diameter": "Data sheet: the round wire's diameter d (instead of rate and mass).",
        "train.spring.coil_diameter": "Data sheet: mean coil diameter D (> 2 d).",
        "train.spring.active_coils": "Data sheet: active coils n_a (rate G d^4/(8 D^3 n_a)).",
        "train.spring.total_coils": "Data sheet: total coils (the wire's mass; solid length n_t d).",
        "train.spring.solid_length": "Data sheet: solid length (default total_coils x wire_diameter).",
        "train.spring.shear_modulus": "Data sheet: the wire's shear modulus G.",
        "train.spring.density": "Data sheet: the wire's density (the spring's mass).",
        "train.spring.tensile_strength": "Data sheet: the wire's tensile strength R_m at its diameter, or \"VDSiCrV\" "
                                         "(R_m = A / d^m fitted to its table), or {A, m}.",
        "train.spring.tensile_strength.A": "R_m = A / d^m: A in MPa mm^m (d in mm).",
        "train.spring.tensile_strength.m": "R_m = A / d^m: the exponent m.",
        "train.spring.wire_height": "Data sheet: elliptic wire's axis along the spring (wire_diameter: the radial one).",
        "train.spring.fatigue_limit": "Data sheet: shear fatigue limit at zero mean (Goodman factor).",
        "train.spring.shear_ratio": "Data sheet: ultimate shear over tensile strength (Goodman line's end).",
        "train.spring.segment_coils": "Pitch diagram: active coils per segment, fixed end first (one bar each).",
        "train.spring.segment_pitches": "Pitch diagram: each segment's free pitch (coil spacing).",
        "train.spring.lengths": "Force-length table: lengths, decreasing (progressive spring).",
        "train.spring.forces": "Force-length table: the force at each length.",
        "train.spring.inner": "A nested inner spring in parallel: the same data-sheet keys.",
        "train.spring.coil_contact": "Pitch diagram: linear coil contacts per segment (default) or none.",
        "train.spring.block_stiffness": "Pitch diagram: a closed segment's contact stiffness (default 100 k_i).",
        "train.spring.block_damping_ratio": "Pitch diagram: coil contact damping, ratio of critical (default 0.1).",
        "checks.spring_stress_max": "Largest corrected shear stress of a data-sheet spring (Bergstraesser).",
        "checks.spring_fatigue_min": "Smallest Goodman fatigue safety factor of a spring over the last cycle.",
        "checks.coil_bind_margin_min": "Smallest length reached minus the solid length.",
        "springs": "Data sheets of the valve springs (a train's data-sheet spring writes them).",
        "springs[].name": "The spring's member name.",
        "springs[].coordinate": "The coordinate of the spring's moving end (retainer).",
        "springs[].nodes": "A pitch diagram's coordinates between its segments (fixed end first).",
        "springs[].contacts": "A pitch diagram's coil-contact clearances, one per segment (fixed end first).",
        "train.cam": "The lift law at the cam (a finger's: the roller's radial lift).",
        "train.cam.law": "Harmonic (the thesis' cam), a lift table or the ramped polydyne.",
        "train.cam.angle_basis": "Angles in cam or crank degrees (crank: halved).",
        "train.cam.lift": "Total lift at the nose.",
        "train.cam.ramp_height": "Polydyne: height of each ramp.",
        "train.cam.ramp_deg": "Polydyne: angle of each ramp.",
        "train.cam.flank_deg": "Polydyne: angle from a ramp's end to the nose.",
        "train.cam.nose_deg": "Polydyne: the nose's cam angle.",
        "train.cam.step_deg": "Polydyne: spacing of the sampled table.",
        "train.cam.tolerance": "Largest lift error the Fourier fit may leave.",
        "train.seat": "The valve seat: by lash or position.",
        "train.seat.lash": "Follower clearance on the base circle (the model's cam coordinate).",
        "train.seat.position": "The seat's position on the valve coordinate.",
        "train.follower": "The follower's geometry ([follower]'s keys; the type sets its arrangement).",
        "train.follower.kind": "A flat face or a roller.",
        "train.follower.friction": "Friction coefficient of the cam-follower contact (its share of the drive torque).",
        "train.follower.guide_friction": "Valve-guide Coulomb friction force (stem side load times its coefficient).",
        "train.follower.guide_velocity": "Regularisation velocity of the guide friction: F = F_g tanh(v / v_r).",
        **{f"train.{key}": meaning for key, meaning in FRICTION_LAWS.items()},
        "train.follower.arrangement": "Set by the type (not given here).",
        "train.follower.base_radius": "The cam's base-circle radius (profile).",
        "train.follower.width": "Length of the line contact.",
        "train.follower.roller_radius": "The roller's radius.",
        "train.follower.cam_modulus": "Young's modulus of the cam.",
        "train.follower.cam_poisson": "Poisson's ratio of the cam.",
        "train.follower.follower_modulus": "Young's modulus of the follower.",
        "train.follower.follower_poisson": "Poisson's ratio of the follower.",
        "train.follower.roller_arm": "Set by the type from train.finger (not given here).",
        "train.follower.valve_arm": "Set by the type from train.finger (not given here).",
        "train.follower.roller_height": "Set by the type from train.finger (not given here).",
        "train.follower.cam_offset": "Set by the type from train.finger (not given here).",
        "train.follower.lift": "Set by the type from train.cam (not given here).",
        "train.follower.oil": "Set by the type from train.oil (not given here).",
        "train.follower.oil.viscosity": "From train.oil.viscosity.",
        "train.follower.oil.pressure_viscosity": "From train.oil.pressure_viscosity.",
        "train.oil": "The oil at the cam contact: viscosity (mPa*s) and pressure_viscosity (1/GPa).",
        "seat.lash": "Lash at the static start; sets the seat position instead of `position`.",
        "members": "The elastic members, one table each ([members.pushrod], ...).",
        "members.*": "One member: its element, section, material and coordinates.",
        "members.*.element": "Axial bar (2 coordinates) or Euler-Bernoulli beam (4).",
        "members.*.length": "The member's length.",
        "members.*.coordinates": "The thesis' beta matrix row: the signed system coordinate of each element "
                                 "coordinate, 0 for a grounded end.",
        "members.*.diameter": "Diameter of a round section (gives area and inertia).",
        "members.*.area": "Cross-section area (instead of a diameter).",
        "members.*.inertia": "Second moment of area (a beam; instead of a diameter).",
        "members.*.modulus": "Young's modulus.",
        "members.*.specific_weight": "Weight per volume (with gravity, the density).",
        "members.*.density": "Mass per volume (instead of a specific weight).",
        "members.*.stiffness": "Axial stiffness of a spring member (instead of a modulus).",
        "members.*.mass": "The member's mass (instead of a density).",
        "members.*.position": "Where the member starts in the drawing (drawing only).",
        "members.*.direction": "The member's angle in the drawing (drawing only).",
        "members.*.elements": "Finite elements the member is split into.",
        "clearances": "The clearances, in the thesis' order (clearance 1 is the configuration's leading bit).",
        "clearances[].name": "The clearance's name in tables and events.",
        "clearances[].kind": "External (against a prescribed coordinate) or internal (between two elastic ones).",
        "clearances[].ahead": "The coordinate ahead: gap = q[ahead] - q[behind], contact when gap <= 0.",
        "clearances[].behind": "The coordinate behind (0: the ground, for a compliant external contact).",
        "clearances[].state": "Enabled, pinned (always closed) or removed (never monitored).",
        "clearances[].restitution": "Coefficient of restitution of its impacts.",
        "clearances[].impact": "Its own impact law (default: contact.impact).",
        "clearances[].contact": "Rigid, linear spring-dashpot or Hertz/Hunt-Crossley contact.",
        "clearances[].contact_stiffness": "Contact stiffness (linear: force per length; Hertz: per length^n).",
        "clearances[].contact_damping": "Contact damping coefficient (linear contact).",
        "clearances[].contact_damping_ratio": "Contact damping as a ratio of critical (linear contact).",
        "clearances[].contact_exponent": "Exponent n of a Hertz contact's force law.",
        "clearances[].opening": "Gap where q[ahead] = q[behind] (compliant contacts; a coil gap), default 0.",
        "clearances[].sense": "+1: gap = q[ahead] - q[behind] + opening; -1: q[behind] - q[ahead] + opening.",
        "initial": "The static start.",
        "initial.closed": "Clearances closed at the start (the starting configuration).",
        "initial.spring_preload": "The valve spring's preload.",
        "initial.lever_ratio": "Follower force per unit spring force at the start.",
        "initial.velocities": "Start velocities: the thesis' or quasi-static.",
        "damping": "Modal damping, per contact layer.",
        "damping.factor": "Factor on every damping ratio.",
        "damping.default_ratio": "Damping ratio of every mode not named otherwise.",
        "damping.layers": "Ratios of one contact layer (the layer with these internal clearances closed).",
        "damping.layers[].closed": "The internal clearances closed in this layer.",
        "damping.layers[].default_ratio": "Damping ratio of this layer's modes not named.",
        "damping.layers[].mode_ratios": "Ratios of single modes of this layer, by mode number.",
        "damping.layers[].mode_ratios.<number>": "The damping ratio of the mode of this number (ascending frequency).",
        "contact": "Impact rules of the rigid clearances.",
        "contact.impact": "Impact law: local (thesis eq. 3.53), thesis (eq. 3.54) or momentum (one LCP).",
        "contact.rocker_scale": "The thesis' SCALE at the rocker (eq. 3.54).",
        "run": "The run: cam speed, length, step, back end, output.",
        "run.rpm": "Cam speed (`vtool solve --rpm`).",
        "run.degrees": "Cam rotation to run (`--degrees`).",
        "run.time_step": "Time step of a fixed-step back end (`--dt`).",
        "run.backend": "The back end that integrates (`--backend`; the installed ones).",
        "run.output_interval": "Cam rotation between output rows.",
        "run.beta": "Newmark's beta (thesis: 1/6).",
        "run.gamma": "Newmark's gamma (thesis: 1/2).",
        "run.quantities": "Extra CSV and chart columns: coordinates (\"q7\", \"q1-q9\") and forces (\"F2\").",
        "run.cycles": "Run this many cam cycles, cycle by cycle; the metrics cover the last (instead of `degrees`).",
        "run.steady": "Run cycle by cycle until the cycle's start state and metrics settle; the last is evaluated.",
        "run.steady.tolerance": "Largest relative change from one cycle to the next that counts as settled.",
        "run.steady.max_cycles": "Cycles after which a run that has not settled stops and says so.",
        "run.jump_angle": "The follower leaves the cam when its contact is open longer than this during lift.",
        "run.jump_gap": "... and its gap exceeds this (default: 0.1 % of the cam's lift).",
        "run.bounce_lift": "The valve bounces when it re-opens after seating by more than this (default: 0.1 % of "
                           "the cam's lift).",
        "run.orders": "Quantities whose cam-order amplitudes are metrics (`QUANTITY_order_K`).",
        "run.highest_order": "The highest cam order of those metrics.",
    },
    "boom_wall": COMMON | BOOM | {
        "walls": "The walls to assess, one table each.",
        "walls[].name": "The wall's name in the results.",
        "walls[].base_width": "Width of the wall's base.",
        "walls[].thickness": "The wall's thickness.",
        "walls[].youngs_modulus": "Young's modulus of the wall.",
        "walls[].poisson_ratio": "Poisson's ratio of the wall.",
        "walls[].surface_weight": "Weight per area of the wall.",
        "walls[].net_area": "Net area (openings removed), for the pseudo-height rule.",
        "walls[].height": "The wall's height (instead of the pseudo height).",
        "walls[].measured_frequency": "A measured natural frequency, used instead of the plate formula.",
        "walls[].pseudo_height_rule": "The pseudo height net_area / base_width as is, or rounded to "
                                      "whole units as the thesis does.",
    },
    "boom_floor": COMMON | BOOM | {
        "floors": "The floors to assess, one table each.",
        "floors[].name": "The floor's name in the results.",
        "floors[].columns": "Columns n carrying the floor (stiffness 12 n E I / l^3).",
        "floors[].youngs_modulus": "Young's modulus of the columns.",
        "floors[].moment_of_inertia": "Second moment of area of one column.",
        "floors[].storey_height": "The storey height l.",
        "floors[].face_width": "Width of the face the boom loads.",
        "floors[].floor_weight": "Weight of the floor.",
        "floors[].measured_frequency": "A measured natural frequency, used instead of the formula.",
    },
    "plate": COMMON | {
        "plate": "The simply supported plate.",
        "plate.a": "Side a (along x).",
        "plate.b": "Side b (along y).",
        "plate.thickness": "The plate's thickness.",
        "plate.youngs_modulus": "Young's modulus.",
        "plate.density": "Mass per volume.",
        "plate.poisson": "Poisson's ratio.",
        "study": "Defaults of every case.",
        "study.element": "Element: 16-DOF (bfs16) or 24-DOF (mason24).",
        "study.mesh": "Mesh NX, NY over the plate.",
        "study.frequencies": "Lowest modes compared with the exact (Navier) frequencies.",
        "study.convergence_meshes": "Meshes of the convergence table.",
        "cases": "The condensed models compared, one table each.",
        "cases[].name": "The case's name in the results.",
        "cases[].element": "The case's element (default: study.element).",
        "cases[].mesh": "The case's mesh (default: study.mesh).",
        "cases[].masters": "The master set: a named set, \"auto\" or node labels.",
        "cases[].method": "Reduction: Irons/Guyan or IRS.",
        "cases[].note": "Free text shown with the case.",
        "cases[].auto": "Masters chosen automatically (with masters = \"auto\").",
        "transient": "Transient step loads (RK4 and exact modal superposition).",
        "transient.cases": "Cases run transient (default: all).",
        "transient.loads": "Step loads: uniform and/or central point.",
        "transient.omega_max_h": "RK4 steps as omega_max * h.",
        "transient.periods": "Length of run in periods of the lowest mode.",
        "transient.exact_modes": "Modes of the exact superposition.",
        "transient.tolerance": "Error above which a transient result is flagged.",
        "transient.truncation_check": "Check the exact superposition's truncation by doubling its modes.",
    },
    "camshaft": {key: COMMON[key] for key in ("kind", "title")} | {
        "camshaft": "The camshaft: its cylinders, firing order, speed and valves (presets/camshaft.py).",
        "camshaft.cylinders": "Number of cylinders whose lobes the camshaft carries.",
        "camshaft.firing_order": "Cylinder numbers in firing order: the k-th fires 360 k / cylinders cam deg "
                                 "after the first.",
        "camshaft.rpm": "Cam speed set into every train (default: each train preset's run.rpm).",
        "camshaft.valves": "One table per valve (lobe) on the camshaft.",
        "camshaft.valves[].train": "The valve's train: a shipped valvetrain preset with a follower, or a file "
                                   "beside this preset.",
        "camshaft.valves[].cylinder": "The valve's cylinder: its phase from the firing order.",
        "camshaft.valves[].phase": "Phase offset of the lobe (an exhaust lobe's), added to its cylinder's.",
        "camshaft.valves[].label": "The valve's name in the tables, CSV header and charts.",
    },
}
# the explicit form's [[springs]] (a data sheet as a train writes it): the same keys as [train.spring]
# and a nested [train.spring.inner]
MEANINGS["valvetrain"] |= {
    f"{table}.{key}": MEANINGS["valvetrain"][f"train.spring.{key}"]
    for table in ("springs[]", "train.spring.inner")
    for key in ("wire_diameter", "coil_diameter", "active_coils", "total_coils", "free_length", "installed_length",
                "solid_length", "shear_modulus", "density", "tensile_strength", "fatigue_limit", "shear_ratio",
                "lengths", "forces", "wire_height")
    + (("segment_coils", "segment_pitches") if table == "springs[]" else ("tensile_strength.A", "tensile_strength.m"))} | {
    "train.spring.inner.elements": "Equal bar elements of the inner spring (surge modes).",
    "train.spring.inner.coil_contact": "Pitch diagram: linear coil contacts per segment (default) or none.",
    "train.spring.inner.block_stiffness": "Pitch diagram: a closed segment's contact stiffness (default 100 k_i).",
    "train.spring.inner.block_damping_ratio": "Pitch diagram: coil contact damping ratio (default 0.1)."}


def _merge(into: dict[str, FieldRead], reads: dict[str, FieldRead]) -> None:
    for path, read in reads.items():
        kept = into.setdefault(path, FieldRead(path, read.type))
        kept.units |= read.units
        kept.allowed |= read.allowed
        kept.defaults |= read.defaults


def field_reads() -> dict[str, dict[str, FieldRead]]:
    """kind -> path -> what the loader read, over the shipped presets and :data:`VARIANTS`."""
    documents: list[tuple[dict[str, Any], Path]] = []
    for info in list_presets():
        documents.append((read_document(info.path), info.path.parent))
    shipped = {info.name: info.path for info in list_presets()}
    for name, changes in VARIANTS:
        doc = set_fields(read_document(shipped[name]), {k: v for k, v in changes.items() if v is not None})
        for path in (k for k, v in changes.items() if v is None):
            table, _, key = path.rpartition(".")
            doc[table].pop(key, None)  # (a key of a top-level table)
        documents.append((doc, shipped[name].parent))
    result: dict[str, dict[str, FieldRead]] = {kind: {} for kind in KINDS}
    for doc, folder in documents:
        with recording() as reads:
            load_document(doc, folder)
        _merge(result[doc["kind"]], reads)
    return result


def _cell(values: set[str], joiner: str = "; ") -> str:
    return joiner.join(sorted(v for v in values if v)).replace("|", "\\|")


def markdown(reads: dict[str, dict[str, FieldRead]] | None = None) -> str:
    """docs/presets.md: one table per kind."""
    reads = field_reads() if reads is None else reads
    lines = ["# Preset reference", "",
             "Every key the loaders read, per preset kind: its type, unit (of each unit system a preset may "
             "declare), allowed values, default and meaning. Generated from the loaders' own reads "
             "(presets/fields.py, presets/reference.py) by `python benchmarks/presets_reference.py --write`; "
             "do not edit by hand. `*` stands for any name (`members.*`: every member), `[]` for any entry "
             "of an array of tables, `<number>` for a key that is a number.", ""]
    for name, kind in KINDS.items():
        lines += [f"## `{name}`: {kind.description}", "",
                  "| key | type | unit | allowed | default | meaning |", "|---|---|---|---|---|---|"]
        meanings = MEANINGS.get(name, {})
        for path, read in reads[name].items():
            default = "required" if REQUIRED in read.defaults else _cell(read.defaults, " or ")
            meaning = _cell({meanings.get(path, "")})
            lines.append(f"| `{path}` | {read.type} | {_cell(read.units, ', ')} | {_cell(read.allowed)} | "
                         f"{default} | {meaning} |")
        lines.append("")
    return "\n".join(lines)


def missing_meanings(reads: dict[str, dict[str, FieldRead]]) -> list[str]:
    """``kind: path`` of every key read without a meaning."""
    return [f"{kind}: {path}" for kind, paths in reads.items() for path in paths
            if path not in MEANINGS.get(kind, {})]


def stale_meanings(reads: dict[str, dict[str, FieldRead]]) -> list[str]:
    """``kind: path`` of every meaning whose key the loader never read."""
    return [f"{kind}: {path}" for kind, meanings in MEANINGS.items() for path in meanings
            if path not in reads.get(kind, {})]
