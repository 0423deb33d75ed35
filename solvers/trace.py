"""The result of a valve-train run, the same for every back end.

A :class:`Trace` holds the sampled response (time, cam angle, coordinates,
velocities, accelerations, contact forces, configuration), the event list,
the peak contact forces seen at every step, and run statistics. It exports
CSV text with units in the header and a summary (separations and impacts per
clearance, peak forces, valve seating velocities, bounces per cam revolution).
"""

from __future__ import annotations

import io
import math
import re
import time as wallclock
from dataclasses import dataclass, field
from typing import Any, overload

import numpy as np

from vtool.files import open_atomic
from vtool.solvers.model.configurations import closed_names, configuration_label, thesis_number
from vtool.solvers.model.spec import ENABLED, EXTERNAL, MechanismSpec
from vtool.solvers.newmark import layout

OPENED = "opened"
CLOSED = "closed"
RELEASED = "released"  # a persistent contact pulled apart by another contact's impact
#: the kernels' event codes (:mod:`vtool.solvers.newmark.layout`) to the kinds above
EVENT_KINDS: dict[int, str] = {int(layout.EV_OPENED): OPENED, int(layout.EV_CLOSED): CLOSED,
                              int(layout.EV_RELEASED): RELEASED}

#: Events at one clearance closer than this (degrees of cam rotation) form one physical episode.
EPISODE_WINDOW_DEG = 0.1
#: A seat re-opening that closes again within this (degrees) is a bounce, not the cam lifting the valve.
BOUNCE_WINDOW_DEG = 90.0
#: a closed rigid contact force below -this share of the run's largest peak force is flagged (Trace.tensile_forces)
TENSILE_FRACTION = 1e-6

#: Episode kinds by the clearance's state before and after the burst of events.
SEPARATION, IMPACT, BOUNCE, FLICKER = "separation", "impact", "bounce", "flicker"


@dataclass(frozen=True)
class Episode:
    """A burst of events at one clearance (each within EPISODE_WINDOW_DEG of the previous).

    ``kind`` by the state before and after: closed -> open ``separation``,
    open -> closed ``impact``, open -> open ``bounce`` (touched and left),
    closed -> closed ``flicker`` (a momentary separation).
    """

    clearance: str
    kind: str
    first_angle: float  # degrees
    last_angle: float
    events: int
    impact_velocity: float | None  # relative velocity of the first impact in it (length/s), if any


@dataclass(frozen=True)
class Event:
    """One configuration change at one clearance.

    ``relative_velocity`` is d(gap)/dt: before the impact for ``closed``
    (negative: approaching), after it for ``released``, zero for ``opened``.
    """

    time: float
    cam_angle: float  # degrees
    clearance: str
    kind: str
    relative_velocity: float
    before: int  # configuration masks
    after: int

    def shifted(self, seconds: float, degrees: float) -> Event:
        """This event ``seconds`` and ``degrees`` later (a run's cycles joined: solvers/studies/steady.py),
        made as :meth:`TraceBuilder.add_events` makes events: dataclasses.replace looks the fields up at every
        call (1.5 s of docs/sweep.md's 21 s regeneration, 244,000 events)."""
        event = object.__new__(Event)
        fields = dict(self.__dict__)
        fields["time"] += seconds
        fields["cam_angle"] += degrees
        object.__setattr__(event, "__dict__", fields)
        return event


@dataclass(frozen=True)
class RunStatistics:
    backend: str
    steps: int
    events: int
    wall_time: float  # s
    configurations_built: tuple[int, ...]
    settings: dict = field(default_factory=dict)
    error_estimate: float | None = None
    compile_time: float = 0.0  # s spent compiling (or loading) the kernel, not in wall_time
    remedy: str = ""  # the back end's advice when a result is not to be trusted (Backend.remedy)


@dataclass(frozen=True)
class Cycles:
    """How a cycle-by-cycle run went (:mod:`vtool.solvers.studies.steady`); the trace holds every cycle.

    ``settled`` is None for a fixed number of cycles (``run.cycles``). ``period`` is the number of cycles
    after which the motion repeats (1; 2 or more for a subharmonic orbit, whose last ``period`` cycles are
    evaluated). ``change`` is the largest relative change of the continuous measures from the cycle a
    period before to the last one, ``changed`` what moved that much, ``events_changed`` how the events per
    clearance differ ("" when they repeat); ``changes`` is the cycle-to-cycle change after each cycle
    (the first has none: NaN; inf where the events differ). ``peaks`` are the every-step peak contact
    forces over the evaluated cycles, ``startup_peaks`` over the first (NaN after a periodic start).
    """

    count: int
    settled: bool | None
    tolerance: float
    change: float
    changed: str
    changes: tuple[float, ...]
    peaks: np.ndarray
    startup_peaks: np.ndarray
    max_cycles: int = 0
    period: int = 1
    events_changed: str = ""

    @property
    def window(self) -> tuple[float, float]:
        """The evaluated cycles' cam angles (deg): the last ``period`` cycles."""
        return 360.0 * (self.count - self.period), 360.0 * self.count

    def text(self) -> str:
        """One line: which cycles are evaluated and whether the run settled."""
        start, end = self.window
        which = (f"cycle {self.count} of {self.count}" if self.period == 1 else
                 f"cycles {self.count - self.period + 1}-{self.count} of {self.count}")
        where = f"{which} (cam angle {start:g}-{end:g} deg)"
        before = "the cycle before" if self.period == 1 else f"the cycle {self.period} before"
        moved = "" if self.count < 2 else f"; the last cycle changed by {self.change:.3g} from {before} ({self.changed})"
        events = f"; events per cycle still change ({self.events_changed})" if self.events_changed else ""
        if self.settled is None:
            return f"evaluated: {where}, a fixed number of cycles (run.cycles){moved}{events}"
        if self.settled:
            period = "" if self.period == 1 else f" repeating every {self.period} cycles (a subharmonic orbit),"
            return f"evaluated: {where},{period} settled to {self.tolerance:g}{moved}"
        return (f"warning: did not settle in {self.count} cycles (run.steady max_cycles = {self.max_cycles}), "
                f"nor repeat every 2 to {MAX_PERIOD} cycles: evaluated {where}{moved}{events}, above the "
                f"tolerance {self.tolerance:g}")


#: the longest period (in cam cycles) a steady run looks for
MAX_PERIOD = 4


@dataclass(frozen=True)
class Trace:
    """Response of one run (see module doc). Rows are output instants."""

    spec: MechanismSpec
    time: np.ndarray
    cam_angle: np.ndarray  # degrees
    coordinate_numbers: tuple[int, ...]  # column numbers of q: elastic, then cam, seat
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    contact_force: np.ndarray  # rows x clearances, compression positive, 0 when open
    configuration: np.ndarray  # masks
    events: tuple[Event, ...]
    peak_force: np.ndarray  # per clearance, over every step
    statistics: RunStatistics
    success: bool = True
    message: str = ""
    peak_force_after_first_revolution: np.ndarray | None = None  # per clearance, over every step
    peak_overlap: np.ndarray | None = None  # per clearance, largest overlap of a compliant contact
    cycles: Cycles | None = None  # a run cycle by cycle (run.cycles, run.steady): how it went
    #: rows x states of the nonlinear elements (solvers/model/nonlinear.py; None: a linear model)
    states: np.ndarray | None = None

    # ----- results that should not be trusted -----
    def tensile_forces(self) -> np.ndarray:
        """Per clearance, the most tensile (negative) force an enabled rigid contact carried while closed,
        over the output rows (0.0: never; compliant and pinned clearances 0.0: they may pull).

        A closed rigid contact only pushes: every back end releases it when its force reaches zero. A
        force below -:data:`TENSILE_FRACTION` of the run's largest peak force is a release the back end
        missed (solve_ivp looks for sign changes only between its own steps: a loose ``rtol`` lets a
        force cross zero and back within one step), and what follows it is not to be trusted.
        """
        result = np.zeros(len(self.spec.clearances))
        if not self.contact_force.size:
            return result
        scale = TENSILE_FRACTION * max(float(np.max(self.peak_force, initial=0.0)), 1e-300)
        if float(self.contact_force.min()) >= -scale:  # no force that low at all (1 µs; a column's min is 2)
            return result
        for k, c in enumerate(self.spec.clearances):
            if c.rigid and c.state == ENABLED:
                least = float(np.min(self.contact_force[:, k]))
                result[k] = least if least < -scale else 0.0
        return result

    def force_sign_warning(self) -> str | None:
        """One line naming the contacts that pulled while closed (:meth:`tensile_forces`), or None."""
        tensile = self.tensile_forces()
        if not tensile.any():
            return None
        unit = self.spec.unit_system.force
        named = []
        for k in np.flatnonzero(tensile):
            row = int(np.argmin(self.contact_force[:, k]))
            named.append(f"{self.force_label(int(k))} ({self.spec.clearances[k].name}) {tensile[k]:.4g} {unit} "
                         f"at {self.cam_angle[row]:.1f} deg")
        backend = self.statistics.backend
        remedy = self.statistics.remedy or "another back end to compare"
        return (f"contact forces of the wrong sign: {', '.join(named)}: a closed contact pulled, a release "
                f"the {backend} back end missed; the events and peaks after it are not to be trusted ({remedy})")

    # ----- columns by the engineer's names -----
    def coordinate(self, number: int, rows: slice = slice(None)) -> np.ndarray:
        return self.q[rows, self.coordinate_numbers.index(number)]

    def cam_clearance_index(self) -> int:
        """The index of the clearance at the cam (the cam coordinate behind it)."""
        return next(i for i, c in enumerate(self.spec.clearances) if c.behind == self.spec.cam.coordinate)

    def force_label(self, index: int) -> str:
        return self.spec.force_label(index)

    def force(self, label_or_name: str, rows: slice = slice(None)) -> np.ndarray:
        for i, c in enumerate(self.spec.clearances):
            if label_or_name in (c.name, self.force_label(i)):
                return self.contact_force[rows, i]
        raise KeyError(label_or_name)

    def quantity(self, expression: str, rows: slice = slice(None)) -> np.ndarray:
        """``q7``, ``q1-q9`` or ``F2`` (the force at the clearance ahead of q2), on a slice of rows."""
        text = expression.replace(" ", "")
        if match := re.fullmatch(r"q(\d+)-q(\d+)", text):
            return self.coordinate(int(match[1]), rows) - self.coordinate(int(match[2]), rows)
        if match := re.fullmatch(r"q(\d+)", text):
            return self.coordinate(int(match[1]), rows)
        if re.fullmatch(r"F\d+", text):
            return self.force(text, rows)
        if self.spec.springs:  # a data-sheet spring's end force (solvers/model/spring.py)
            from vtool.solvers.model.spring import end_force, force_quantity

            for spring in self.spec.springs:
                if text == force_quantity(spring):
                    return end_force(spring, self, rows)
        raise KeyError(expression)

    def coordinate_unit(self, number: int) -> str:
        units = self.spec.unit_system
        if number <= self.spec.n_coordinates and self.spec.coordinates[number - 1].motion == "rotation":
            return "rad"
        return units.length

    def quantity_unit(self, expression: str) -> str:
        text = expression.replace(" ", "")
        if text.startswith("F") or text.endswith("_force"):
            return self.spec.unit_system.force
        return self.coordinate_unit(int(re.findall(r"\d+", text)[0]))

    # ----- export -----
    def valve_coordinate(self) -> int | None:
        """The number of the coordinate that seats (ahead of the seat clearance), or None without a seat."""
        seat = self.spec.seat
        if seat is None:
            return None
        for c in self.spec.clearances:
            if c.kind == EXTERNAL and c.behind == seat.coordinate and c.ahead in self.coordinate_numbers:
                return c.ahead
        return None

    def valve_lift(self, rows: slice = slice(None)) -> np.ndarray:
        """Valve lift off its seat: the seat clearance's gap ``q_valve - q_seat`` (length; 0 when seated)."""
        valve = self.valve_coordinate()
        if valve is None or self.spec.seat is None:
            raise KeyError("valve_lift")
        seat = self.spec.seat.coordinate
        if seat in self.coordinate_numbers:
            return self.coordinate(valve, rows) - self.coordinate(seat, rows)
        return self.coordinate(valve, rows) - self.spec.seat.position

    def csv_columns(self, quantities: tuple[str, ...] = ()) -> tuple[list[str], list]:
        """The CSV header (quantity names with units) and one function per numeric column that gives
        the column's values on a slice of rows (so a long run is written block by block).

        Every name is unique: a preset quantity that is already a column (``q9``, ``F1``: the thesis
        presets list seven) or is listed twice is written once. ``valve_lift`` (the seat clearance's
        gap, :meth:`valve_lift`) follows the contact forces when the preset has a seat.
        """
        units = self.spec.unit_system
        header = ["time (s)", "cam_angle (deg)"]
        columns: list = [lambda rows: self.time[rows], lambda rows: self.cam_angle[rows]]
        for prefix, data, suffix in (("q", self.q, ""), ("qd", self.qd, f"/{units.time}"),
                                     ("qdd", self.qdd, f"/{units.time}^2")):
            for j, number in enumerate(self.coordinate_numbers):
                header.append(f"{prefix}{number} ({self.coordinate_unit(number)}{suffix})")
                columns.append(lambda rows, data=data, j=j: data[rows, j])
        for i in range(len(self.spec.clearances)):
            header.append(f"{self.force_label(i)} ({units.force})")
            columns.append(lambda rows, i=i: self.contact_force[rows, i])
        if self.valve_coordinate() is not None:
            header.append(f"valve_lift ({units.length})")
            columns.append(self.valve_lift)
        if self.spec.springs:  # each data-sheet spring's force on its end (spring.end_force)
            from vtool.solvers.model.spring import force_quantity

            for name in map(force_quantity, self.spec.springs):
                header.append(f"{name} ({units.force})")
                columns.append(lambda rows, name=name: self.quantity(name, rows))
        names = {h.rpartition(" (")[0] for h in header}
        for expression in quantities:
            name = expression.replace(" ", "")
            if name in names:
                continue
            names.add(name)
            header.append(f"{name} ({self.quantity_unit(expression)})")
            columns.append(lambda rows, expression=expression: self.quantity(expression, rows))
        if self.spec.follower is not None:  # cam contact stress at each row (solvers/model/camstress.py)
            from vtool.solvers.model.camstress import row_unit, stress_rows

            cam = next(i for i, c in enumerate(self.spec.clearances) if c.behind == self.spec.cam.coordinate)
            for name in list(stress_rows(self.spec, self.cam_angle[:1], self.contact_force[:1, cam])):
                header.append(f"cam_{name} ({row_unit(self.spec, name)})")
                columns.append(lambda rows, name=name: stress_rows(
                    self.spec, self.cam_angle[rows], self.contact_force[rows, cam])[name])
        if self.spec.follower is not None:  # drive torque and friction (solvers/studies/torque.py)
            from vtool.solvers.studies import torque

            cam = self.cam_clearance_index()
            whole = torque.torque_rows(self.spec, self.cam_angle, self.contact_force[:, cam]) \
                if torque.whole_run(self.spec) else None  # (a roller's slip: each row depends on those before)
            for name in torque.row_names(self.spec):
                header.append(f"cam_{name} ({torque.row_unit(self.spec, name)})")
                columns.append(lambda rows, name=name: getattr(whole, name)[rows] if whole is not None else getattr(
                    torque.torque_rows(self.spec, self.cam_angle[rows], self.contact_force[rows, cam]), name))
            valve = self.valve_coordinate()
            if self.spec.follower.guide_friction > 0.0 and valve is not None:
                j = self.coordinate_numbers.index(valve)
                for k, name in enumerate(("valve_guide_friction_force", "valve_guide_friction_power")):
                    header.append(f"{name} ({torque.row_unit(self.spec, name.removeprefix('valve_guide_'))})")
                    columns.append(lambda rows, k=k: torque.guide_rows(self.spec, self.qd[rows, j])[k])
        for name, unit, column in self.element_columns():
            header.append(f"{name} ({unit})")
            columns.append(column)
        return header + ["configuration", "closed"], columns

    def element_columns(self) -> list[tuple[str, str, Any]]:
        """(name, unit, values on a slice of rows) of every nonlinear element's output column (an HLA's
        chamber pressure, plunger extension, flows: solvers/model/nonlinear.py)."""
        if self.states is None:
            return []
        from vtool.solvers.model.attached import elements_of

        elements = elements_of(self.spec)
        n = self.spec.n_coordinates
        result = []
        for element, part in zip(elements.elements, elements.slices, strict=True):
            def values(rows, element=element, part=part):  # noqa: ANN001, ANN202 (a slice; all columns)
                return element.columns(self.time[rows], self.q[rows, :n].T, self.qd[rows, :n].T,
                                       self.states[rows, part].T)
            for index, (name, unit, _) in enumerate(values(slice(0, 1))):
                result.append((name, unit, lambda rows, values=values, index=index: values(rows)[index][2]))
        return result

    def element_summary(self) -> dict:
        """Each nonlinear element's summary entry, by its key (``hla``)."""
        if self.states is None or not len(self.time):
            return {}
        from vtool.solvers.model.attached import elements_of

        elements = elements_of(self.spec)
        return {element.key: element.summary(self, self.states[:, part].T)
                for element, part in zip(elements.elements, elements.slices, strict=True)}

    def configuration_csv(self, mask: int) -> str:
        """The last two CSV columns of a configuration: its thesis number (or nothing) and closed clearances."""
        from vtool.csvrows import csv_text

        number = thesis_number(self.spec, mask)
        return csv_text([["" if number is None else number,
                          "+".join(closed_names(self.spec, mask)) or "none"]]).removesuffix("\n")

    def write_csv_to(self, handle, quantities: tuple[str, ...] = (), chunk: int = 20_000,
                     header: bool = True, compiled: bool | None = None) -> None:
        """Write the CSV in blocks of ``chunk`` rows (memory stays bounded by the block, not the run).

        Numbers are ``'%.10g' % value`` (:func:`vtool.csvrows.write_rows` writes the same text
        about 5x faster; ``compiled`` as there: by default, for a large table or when compiled
        already); ``header=False`` leaves out the header row (a block of a streamed run).
        """
        from vtool.csvrows import write_rows

        names, columns = self.csv_columns(quantities)
        if header:
            handle.write(",".join(names) + "\n")
        masks = np.unique(self.configuration)
        labels = [self.configuration_csv(int(mask)) for mask in masks]
        for start in range(0, len(self.time), chunk):
            rows = slice(start, min(start + chunk, len(self.time)))
            block = np.column_stack([column(rows) for column in columns])
            write_rows(handle, block, labels, np.searchsorted(masks, self.configuration[rows]),
                       compiled=compiled if compiled is not None or len(self.time) < chunk else True)

    def csv_text(self, quantities: tuple[str, ...] = ()) -> str:
        """CSV with one header row naming each quantity and its unit."""
        buffer = io.StringIO()
        self.write_csv_to(buffer, quantities)
        return buffer.getvalue()

    def write_csv(self, path: str, quantities: tuple[str, ...] | None = None, field: str = "output") -> None:
        """Write the CSV atomically, block by block (the preset's quantities by default)."""
        with open_atomic(path, field) as handle:
            self.write_csv_to(handle, self.spec.run.quantities if quantities is None else quantities)

    # ----- summary -----
    def events_at(self, clearance: str, kinds: tuple[str, ...]) -> list[Event]:
        return [e for e in self.events if e.clearance == clearance and e.kind in kinds]

    def bounces_per_revolution(self, clearance: str) -> list[int]:
        """Impacts at a clearance in each whole cam revolution after the first."""
        revolutions = int(self.cam_angle[-1] // 360.0) if len(self.cam_angle) else 0
        counts = [0] * max(revolutions - 1, 0)
        for e in self.events_at(clearance, (CLOSED,)):
            index = int(e.cam_angle // 360.0) - 1
            if 0 <= index < len(counts):
                counts[index] += 1
        return counts

    def episodes(self, clearance: str, window_deg: float = EPISODE_WINDOW_DEG) -> list[Episode]:
        """The physical episodes at a clearance (see :class:`Episode`)."""
        index = next(i for i, c in enumerate(self.spec.clearances) if c.name == clearance)
        bit = 1 << (len(self.spec.clearances) - 1 - index)
        events = [e for e in self.events if e.clearance == clearance]
        groups: list[list[Event]] = []
        for e in events:
            if groups and e.cam_angle - groups[-1][-1].cam_angle <= window_deg:
                groups[-1].append(e)
            else:
                groups.append([e])
        result = []
        for group in groups:
            was, now = bool(group[0].before & bit), bool(group[-1].after & bit)
            kind = {(True, False): SEPARATION, (False, True): IMPACT, (False, False): BOUNCE,
                    (True, True): FLICKER}[(was, now)]
            impacts = [e.relative_velocity for e in group if e.kind == CLOSED]
            result.append(Episode(clearance, kind, group[0].cam_angle, group[-1].cam_angle, len(group),
                                  impacts[0] if impacts else None))
        return result

    def seat_bounces(self, clearance: str) -> list[tuple[float, float, float]]:
        """(opening angle, closing angle, largest gap) of each bounce at a seat-like clearance.

        A bounce is a re-opening after an impact that closes again within
        BOUNCE_WINDOW_DEG; its height is the largest gap over the output rows in
        between (at the output interval: use --every-step for the true peak).
        """
        c = next(c for c in self.spec.clearances if c.name == clearance)
        gap = self.coordinate(c.ahead) - self.coordinate(c.behind)
        result = []
        last_closed = None
        opened_at = None
        for e in self.events:
            if e.clearance != clearance:
                continue
            if e.kind == CLOSED:
                if opened_at is not None and last_closed is not None and e.cam_angle - opened_at <= BOUNCE_WINDOW_DEG:
                    inside = (self.cam_angle >= opened_at) & (self.cam_angle <= e.cam_angle)
                    height = float(gap[inside].max()) if inside.any() else 0.0
                    result.append((opened_at, e.cam_angle, max(height, 0.0)))
                last_closed, opened_at = e.cam_angle, None
                continue
            opened_at = e.cam_angle
        return result

    def summary(self) -> dict:
        """Counts, peaks and seating velocities per clearance, and the run statistics."""
        units = self.spec.unit_system
        clearances = []
        late = self.peak_force_after_first_revolution
        tensile = self.tensile_forces()
        for i, c in enumerate(self.spec.clearances):
            impacts = self.events_at(c.name, (CLOSED,))
            episodes = self.episodes(c.name)
            entry: dict[str, Any] = {
                "clearance": c.name,
                "force": self.force_label(i),
                "state": c.state,
                "impact_law": self.spec.impact_law(c) if c.rigid else None,  # compliant: see "contact"
                "events": sum(e.clearance == c.name for e in self.events),
                "separations": len(self.events_at(c.name, (OPENED, RELEASED))),
                "impacts": len(impacts),
                "episodes": {kind: sum(e.kind == kind for e in episodes)
                             for kind in (SEPARATION, IMPACT, BOUNCE, FLICKER)},
                "peak_force": float(self.peak_force[i]),
                "peak_force_after_first_revolution": None if late is None else float(late[i]),
                "peak_force_unit": units.force,
                "tensile_force": float(tensile[i]),  # the most tensile force while closed: 0 unless it pulled
                "contact": c.contact,
            }
            if not c.rigid and self.peak_overlap is not None:
                entry["peak_overlap"] = float(self.peak_overlap[i])
                entry["peak_overlap_unit"] = units.length
            if c.kind == EXTERNAL and c.behind not in (self.spec.cam.coordinate, 0):  # 0: the ground (a coil)
                entry["seating_velocities"] = [-e.relative_velocity for e in impacts]
                entry["seating_velocity_unit"] = units.velocity
                entry["bounces_per_revolution"] = self.bounces_per_revolution(c.name)
                seatings = [(e.first_angle, -e.impact_velocity) for e in episodes if e.impact_velocity is not None]
                entry["seating_velocities_per_revolution"] = [
                    [v for angle, v in seatings if int(angle // 360.0) == r + 1]
                    for r in range(len(entry["bounces_per_revolution"]))]
                bounces = self.seat_bounces(c.name)
                entry["bounce_heights_per_revolution"] = [
                    [h for opened, _, h in bounces if int(opened // 360.0) == r + 1]
                    for r in range(len(entry["bounces_per_revolution"]))]
                entry["bounce_height_unit"] = units.length
            clearances.append(entry)
        stats = self.statistics
        return {
            "title": self.spec.title,
            "success": self.success,
            "message": self.message,
            "backend": stats.backend,
            "settings": stats.settings,
            "steps": stats.steps,
            "events": stats.events,
            "wall_time_s": stats.wall_time,
            "compile_time_s": stats.compile_time,
            "episode_window_deg": EPISODE_WINDOW_DEG,
            "configurations_built": [configuration_label(self.spec, m) for m in stats.configurations_built],
            "events_list": [
                {"time_s": e.time, "cam_angle_deg": e.cam_angle, "clearance": e.clearance, "kind": e.kind,
                 "relative_velocity": e.relative_velocity,
                 "before": configuration_label(self.spec, e.before), "after": configuration_label(self.spec, e.after)}
                for e in self.events
            ],
            "clearances": clearances,
            "warnings": [w for w in (self.force_sign_warning(),) if w is not None],
        } | self.follower_summary()

    def follower_summary(self) -> dict:
        """The cam contact's stress extremes (with a [follower]) and the [checks] judged (with limits)."""
        result: dict = {}
        if self.spec.follower is not None:
            from vtool.solvers.model.camstress import stress_summary

            cam = next(c.name for c in self.spec.clearances if c.behind == self.spec.cam.coordinate)
            result["contact_stress"] = stress_summary(self.spec, self.cam_angle, self.force(cam))
        if self.spec.follower is not None:  # drive torque over the last whole revolution
            from vtool.solvers.studies import torque

            window = torque.last_revolution(self.cam_angle)
            if window is not None:
                rows = torque.torque_rows(self.spec, self.cam_angle, self.contact_force[:, self.cam_clearance_index()])
                result["cam_torque"] = torque.torque_summary(self.spec, rows, *window)
                valve = self.valve_coordinate()
                if self.spec.follower.guide_friction > 0.0 and valve is not None:
                    keep = self.cam_angle >= window[0] - 1e-9
                    power = torque.guide_rows(self.spec, self.qd[keep, self.coordinate_numbers.index(valve)])[1]
                    result["cam_torque"]["mean_guide_friction_power"] = float(
                        np.trapezoid(power, self.cam_angle[keep]) / 360.0)
        if self.spec.springs:
            from vtool.solvers.model.spring import run_report

            result["springs"] = run_report(self.spec.springs, self)
        result |= self.element_summary()
        if self.spec.checks:
            from vtool.solvers.studies.checks import evaluate

            result["checks"] = [c.as_dict() for c in evaluate(self.spec, self)]
        return result

    def summary_text(self) -> str:
        s = self.summary()
        units = self.spec.unit_system
        lines = [s["title"], f"back end {s['backend']}: " + ", ".join(f"{k} = {v}" for k, v in s["settings"].items())]
        compiling = (f" (+ {s['compile_time_s']:.1f} s compiling or loading the solver)"
                     if s["compile_time_s"] >= 0.5 else "")
        lines.append(
            f"steps {s['steps']}, events {s['events']}, wall time {s['wall_time_s']:.3f} s{compiling}, "
            f"configurations built: {', '.join(s['configurations_built'])}"
        )
        lines.append("")
        lines.append(f"{'clearance':<10} {'force':<6} {'state':<8} {'law':<8} {'separations':>11} {'impacts':>8} "
                     f"{'peak force (' + units.force + ')':>18}")
        for c in s["clearances"]:
            lines.append(f"{c['clearance']:<10} {c['force']:<6} {c['state']:<8} {c['impact_law'] or c['contact']:<8} "
                         f"{c['separations']:>11} {c['impacts']:>8} {c['peak_force']:>18.6g}")
        for c in s["clearances"]:
            if "peak_overlap" in c:
                lines.append(f"  {c['clearance']}: {c['contact']} contact, peak overlap "
                             f"{c['peak_overlap']:.6g} {c['peak_overlap_unit']}")
        lines.append("")
        lines.append(f"episodes (events at one clearance within {s['episode_window_deg']:g} deg are one):")
        for c in s["clearances"]:
            ep = c["episodes"]
            lines.append(f"  {c['clearance']:<10} {c['events']:>4} events: {ep[SEPARATION]} separations, "
                         f"{ep[IMPACT]} impacts, {ep[BOUNCE]} bounces, {ep[FLICKER]} flickers")
        for c in s["clearances"]:
            if "seating_velocities" in c and c["seating_velocities"]:
                v = np.array(c["seating_velocities"])
                lines.append(
                    f"{c['clearance']} seating velocity ({units.velocity}): first {v[0]:.4g}, "
                    f"max {v.max():.4g}, mean {v.mean():.4g} over {len(v)} impacts"
                )
                lines.append(f"{c['clearance']} bounces per revolution (after the first): "
                             f"{c['bounces_per_revolution']}")
                heights = [max(h) if h else 0.0 for h in c["bounce_heights_per_revolution"]]
                if any(heights):
                    lines.append(f"{c['clearance']} largest bounce height per revolution ({c['bounce_height_unit']}, "
                                 f"at the output interval): " + ", ".join(f"{h:.4g}" for h in heights))
        if "contact_stress" in s:
            from vtool.solvers.model.camstress import stress_text

            lines += stress_text(s["contact_stress"])
        if "cam_torque" in s:
            from vtool.solvers.studies.torque import torque_text

            lines += torque_text(s["cam_torque"])
        if self.states is not None:
            from vtool.solvers.model.attached import elements_of

            for element in elements_of(self.spec).elements:
                if element.key in s:
                    lines += element.summary_text(s[element.key])
        if "springs" in s:
            from vtool.solvers.model.spring import report_text

            lines += report_text(s["springs"], units)
        if "checks" in s:
            from vtool.solvers.studies.checks import checks_text

            lines += checks_text(s["checks"])
        if not s["success"]:
            lines.append(f"run stopped: {s['message']}")
        return "\n".join(lines)

    def event_table(self) -> str:
        units = self.spec.unit_system
        lines = [f"{'cam angle (deg)':>15} {'time (s)':>12} {'clearance':<10} {'event':<9} "
                 f"{'rel. velocity (' + units.velocity + ')':>24}  configuration"]
        for e in self.events:
            lines.append(
                f"{e.cam_angle:>15.4f} {e.time:>12.6e} {e.clearance:<10} {e.kind:<9} "
                f"{e.relative_velocity:>24.5g}  {configuration_label(self.spec, e.before)} -> "
                f"{configuration_label(self.spec, e.after)}"
            )
        return "\n".join(lines)


@overload
def cam_angle_deg(time: np.ndarray, omega: float) -> np.ndarray: ...
@overload
def cam_angle_deg(time: float, omega: float) -> float: ...
def cam_angle_deg(time: np.ndarray | float, omega: float) -> np.ndarray | float:
    """Cam angle in degrees at time(s) t (s) for a cam speed omega (rad/s): an array for an array,
    a float for a float (with no array made for it: one per event)."""
    return time * omega * 180.0 / math.pi


class CsvStream:
    """A run's CSV written as the back end produces its rows (``vtool solve --csv``).

    The :class:`TraceBuilder` hands every block of rows to :meth:`write` at
    once (formatted by :meth:`Trace.write_csv_to`, in the same text as a
    trace's CSV), so the file grows during the run, in the temporary file of
    :func:`vtool.files.open_atomic` (renamed over the target only when the run
    succeeds). Rows must arrive in time order (every back end's do); a block
    that goes back in time is a :class:`~vtool.errors.RunError`, never a
    silently shuffled file.

    With ``thin`` (``--every-step``), the :class:`Trace` the run returns keeps
    only a subset of the rows, so memory stays bounded whatever the length of
    the run (about two rows per output interval, not one per step): the first
    row of each output interval and of each configuration change, the last row,
    and in each stretch of constant configuration within an output interval the
    row of largest gap of every seat-like clearance, so the summary's bounce
    heights (the largest gap between an opening and the next closing) are those
    of every step. The file has every row; :attr:`rows` counts them.
    """

    def __init__(self, handle, quantities: tuple[str, ...] = (), thin: bool = False) -> None:
        self.handle = handle
        self.quantities = tuple(quantities)
        self.thin = thin
        self.rows = 0
        self.seconds = 0.0  # spent formatting and writing (not counted in the run's wall time)
        self.last_time = -math.inf
        self.header_written = False

    def check_order(self, block: Trace) -> None:
        """A block that goes back in time is a RunError (see the class doc)."""
        if len(block.time):
            if block.time[0] < self.last_time or np.any(np.diff(block.time) < 0.0):
                from vtool.errors import RunError

                raise RunError(f"rows out of time order at t = {block.time[0]:.6g} s: the file cannot be "
                               "streamed (a back end must hand rows over in time order)")
            self.last_time = float(block.time[-1])

    def write(self, block: Trace) -> None:
        """Append a block of rows (a :class:`Trace` of its rows)."""
        started = wallclock.perf_counter()
        self.check_order(block)
        block.write_csv_to(self.handle, self.quantities, header=not self.header_written,
                           compiled=True if self.thin else None)
        self.header_written = True
        self.rows += len(block.time)
        self.seconds += wallclock.perf_counter() - started


class TraceBuilder:
    """Collects a run's output rows and events as a back end produces them, then builds the Trace.

    Rows arrive in blocks (arrays), in time order: time, the (x, v, a) of
    every coordinate and source ``q3[rows, 3, n + ns]``, contact forces and
    configuration masks. Every back end builds its trace here, so they share
    one format. With a :class:`CsvStream` each block is also written to the
    CSV at once (and, when the stream thins, only some rows are kept).
    """

    def __init__(self, spec: MechanismSpec, source_numbers: tuple[int, ...], omega: float,
                 stream: CsvStream | None = None) -> None:
        self.spec = spec
        # the unit source (number 0: the constant of clearances with an opening) is no output column: it is
        # the last source, and its column is cut from every block (add_rows)
        self.source_numbers = tuple(number for number in source_numbers if number != 0)
        self.omega = omega
        self.stream = stream
        self.blocks: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        self.state_blocks: list[np.ndarray] = []  # the nonlinear elements' states, block by block (if any)
        self.events: list[Event] = []
        self.numbers = tuple(range(1, spec.n_coordinates + 1)) + self.source_numbers
        self.out_dt = spec.run.output_interval * math.pi / 180.0 / omega if omega > 0 else math.inf
        ncl = len(spec.clearances)
        self.seats = [(self.numbers.index(c.ahead), self.numbers.index(c.behind), 1 << (ncl - 1 - i))
                      for i, c in enumerate(spec.clearances)
                      if c.kind == EXTERNAL and c.behind != spec.cam.coordinate
                      and c.ahead in self.numbers and c.behind in self.numbers]

    def block_trace(self, t: np.ndarray, q3: np.ndarray, F: np.ndarray, cfg: np.ndarray,
                    states: np.ndarray | None = None) -> Trace:
        """A Trace of one block of rows (no events or statistics): what the CSV writer reads."""
        empty = RunStatistics("", 0, 0, 0.0, ())
        return Trace(self.spec, t, cam_angle_deg(t, self.omega), self.numbers, q3[:, 0], q3[:, 1], q3[:, 2], F,
                     cfg, (), np.zeros(len(self.spec.clearances)), empty, states=states)

    def thinned(self, t: np.ndarray, q3: np.ndarray, cfg: np.ndarray) -> np.ndarray:
        """The rows of a block a thinning stream keeps (see :class:`CsvStream`), as a boolean mask."""
        interval = np.floor(t / self.out_dt)
        starts = np.ones(len(t), dtype=bool)
        starts[1:] = (interval[1:] != interval[:-1]) | (cfg[1:] != cfg[:-1])
        keep = starts.copy()
        keep[-1] = True
        stretch = np.cumsum(starts) - 1
        first = np.flatnonzero(starts)
        for ahead, behind, bit in self.seats:
            is_open = (cfg & bit) == 0
            if not is_open.any():
                continue
            gap = np.where(is_open, q3[:, 0, ahead] - q3[:, 0, behind], -np.inf)
            top = np.maximum.reduceat(gap, first)
            at_top = np.flatnonzero(is_open & (gap == top[stretch]))
            keep[at_top[np.unique(stretch[at_top], return_index=True)[1]]] = True
        return keep

    def add_rows(self, t: np.ndarray, q3: np.ndarray, F: np.ndarray, cfg: np.ndarray, copy: bool = True,
                 states: np.ndarray | None = None) -> None:
        """Take a block of rows. ``copy=False``: the caller never writes these arrays again, so the
        builder keeps them as they are (and the trace may too, see :meth:`build`). ``states``: the
        nonlinear elements' states at the rows (rows x states), from a back end that takes elements."""
        if not len(t):
            return
        q3 = q3[:, :, :len(self.numbers)]
        if self.stream is not None:
            self.stream.write(self.block_trace(t, q3, F, cfg, states))
            if self.stream.thin:
                keep = self.thinned(t, q3, cfg)
                t, q3, F, cfg = t[keep], q3[keep], F[keep], cfg[keep]
                states = None if states is None else states[keep]
        if states is not None:
            self.state_blocks.append(np.array(states, dtype=float))
        how = True if copy else None  # None: a copy only where numpy must make one (another dtype)
        self.blocks.append((np.array(t, dtype=float, copy=how), np.array(q3, dtype=float, copy=how),
                            np.array(F, dtype=float, copy=how), np.array(cfg, dtype=np.int64, copy=how)))

    def add_events(self, floats: np.ndarray, ints: np.ndarray) -> None:
        """Take the rows of a kernel's event buffers (:mod:`vtool.solvers.newmark.layout`): ``floats`` holds
        (time, relative velocity), ``ints`` (clearance, event code, configuration before, after). Equal to
        :meth:`add_event` row by row, with less Python around each :class:`Event`."""
        if not len(ints):
            return
        names = [c.name for c in self.spec.clearances]
        times, velocities = floats[:, 0].tolist(), floats[:, 1].tolist()
        angles = np.asarray(cam_angle_deg(floats[:, 0], self.omega)).tolist()
        # Each Event's fields given whole as its __dict__, where a frozen dataclass keeps them: its __init__
        # sets them one by one through object.__setattr__ (1A's 59 events: 115 -> 34 µs; the same objects,
        # equal and hashed alike, still frozen; tests/test_newmark.py compares them with Event(...)).
        new, put = object.__new__, object.__setattr__
        made = []
        for t, angle, u, (k, kind, before, after) in zip(times, angles, velocities, ints.tolist(), strict=True):
            event = new(Event)
            put(event, "__dict__", {"time": t, "cam_angle": angle, "clearance": names[k], "kind": EVENT_KINDS[kind],
                                    "relative_velocity": u, "before": before, "after": after})
            made.append(event)
        self.events += made

    def add_event(self, t: float, clearance: int, kind: str, relative_velocity: float, before: int,
                  after: int) -> None:
        t = float(t)
        self.events.append(Event(t, float(cam_angle_deg(t, self.omega)),
                                 self.spec.clearances[clearance].name, kind, float(relative_velocity),
                                 int(before), int(after)))

    def build(self, peak: np.ndarray, statistics: RunStatistics, peak_late: np.ndarray | None = None,
              sort: bool = False, peak_overlap: np.ndarray | None = None) -> Trace:
        n = self.spec.n_coordinates + len(self.source_numbers)
        ncl = len(self.spec.clearances)
        rows = sum(len(b[0]) for b in self.blocks)
        states = np.concatenate(self.state_blocks) if self.state_blocks else None
        self.state_blocks = []
        if len(self.blocks) == 1:  # the block's own arrays (a copy only where one is not contiguous)
            bt, bq, bF, bc = self.blocks.pop()
            t, F, cfg = np.ascontiguousarray(bt), np.ascontiguousarray(bF), np.ascontiguousarray(bc)
            q, qd, qdd = (np.ascontiguousarray(bq[:, i]) for i in range(3))
        else:
            t, F, cfg = np.zeros(rows), np.zeros((rows, ncl)), np.zeros(rows, dtype=np.int64)
            q, qd, qdd = np.zeros((rows, n)), np.zeros((rows, n)), np.zeros((rows, n))
        start = 0
        while self.blocks:  # copy block by block, freeing each: the peak is the result plus one block
            bt, bq, bF, bc = self.blocks.pop(0)
            stop = start + len(bt)
            t[start:stop], F[start:stop], cfg[start:stop] = bt, bF, bc
            q[start:stop], qd[start:stop], qdd[start:stop] = bq[:, 0], bq[:, 1], bq[:, 2]
            start = stop
        if sort:
            if self.stream is not None:
                from vtool.errors import RunError

                raise RunError("this back end hands rows over out of time order: its CSV cannot be streamed")
            order = np.argsort(t, kind="stable")
            t, q, qd, qdd, F, cfg = t[order], q[order], qd[order], qdd[order], F[order], cfg[order]
            states = None if states is None else states[order]
        if self.stream is not None and not self.stream.header_written:  # a run without rows: the header alone
            self.stream.write(self.block_trace(t, np.zeros((0, 3, n)), F, cfg))
        return Trace(self.spec, t, cam_angle_deg(t, self.omega), self.numbers, q, qd, qdd, F, cfg,
                     tuple(self.events), np.array(peak, dtype=float), statistics,
                     peak_force_after_first_revolution=None if peak_late is None else np.array(peak_late),
                     peak_overlap=None if peak_overlap is None else np.array(peak_overlap, dtype=float),
                     states=states)
