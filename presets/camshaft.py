"""Camshaft presets (kind ``camshaft``): several valve trains on one camshaft.

A camshaft preset names its valves' train presets and their phases::

    kind = "camshaft"
    title = "..."
    [camshaft]
    cylinders = 4
    firing_order = [1, 3, 4, 2]
    rpm = 3000.0                     # cam rev/min, set into every train (optional: the trains' own)
    [[camshaft.valves]]
    train = "ohc-finger-follower"    # a shipped valvetrain preset, or a path beside this file
    cylinder = 1                     # its phase from the firing order ...
    phase = 0.0                      # ... plus this offset, cam deg (an exhaust lobe's); without
                                     # cylinder: the phase alone
    label = "cylinder 1 intake A"    # optional

It is a preset kind of :mod:`vtool.presets.kinds` like any other: shipped
beside the other presets (``four-cylinder-intake``), run by ``vtool solve``
(``vtool camshaft`` is the same command under its old name), shown by the
TUI's camshaft screen (:mod:`vtool.app.tui.camshaft`). ``vtool solve --rpm``
sets ``camshaft.rpm``.

Each distinct train (preset and speed) is run once
(:func:`vtool.solvers.run.simulate`); its drive torque over its last whole
revolution (:mod:`vtool.solvers.studies.torque`) is shifted by each valve's
phase and summed (:mod:`vtool.solvers.studies.camshaft`). Every train must
have a ``[follower]`` (a train type gives one): the torque needs the contact
geometry, and all trains share the camshaft's unit system.

The charts (:func:`camshaft_chart`, :func:`train_torque_chart`) are data
(:class:`vtool.chart.Chart`): the terminal, ``--figure`` and the docs'
figures draw them in ``app/``.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from vtool.errors import InputError
from vtool.presets.fields import Table

MAX_VALVES = 64


@dataclass(frozen=True)
class ValveSpec:
    label: str
    train: str  # as the preset names it
    path: Path  # the train preset it found
    phase_deg: float  # the lobe's phase: the cylinder's from the firing order plus the offset
    cylinder: int | None = None
    offset_deg: float = 0.0


@dataclass(frozen=True)
class CamshaftSpec:
    title: str
    rpm: float | None
    valves: tuple[ValveSpec, ...]
    cylinders: int = 1
    firing_order: tuple[int, ...] = (1,)
    kind: str = "camshaft"


def _train_path(t: Table, folder: Path | None) -> tuple[str, Path]:
    from vtool.presets import find_preset

    name = t.string("train")
    beside = (folder or Path(".")) / name
    if beside.is_file():
        return name, beside
    try:
        return name, find_preset(name)
    except InputError:
        raise InputError(t.field("train"), name, "a shipped valvetrain preset or a file beside the camshaft "
                         "preset") from None


def load(doc: dict[str, Any], folder: Path | None = None) -> CamshaftSpec:
    """Validate a camshaft document (module doc); ``folder``: where a train file it names is looked for."""
    from vtool.solvers.studies.camshaft import cylinder_phases

    top = Table(doc, "")
    top.string("kind", choices=("camshaft",))
    title = top.string("title", default="camshaft")
    shaft = top.table("camshaft")
    cylinders = shaft.integer("cylinders", default=1, min_value=1, max_value=16)
    order = tuple(range(1, cylinders + 1))
    if shaft.has("firing_order"):
        given = shaft.numbers("firing_order")
        if any(v != int(v) for v in given):
            raise InputError(shaft.field("firing_order"), given, f"cylinder numbers 1..{cylinders}")
        order = tuple(int(v) for v in given)
    phases = cylinder_phases(cylinders, order)
    rpm = shaft.number("rpm", unit="rev/min", required=False, min_exclusive=0.0, max_value=1e5) \
        if shaft.has("rpm") else None
    rows = shaft.array_of_tables("valves")
    if not rows or len(rows) > MAX_VALVES:
        raise InputError(shaft.field("valves"), len(rows), f"1 to {MAX_VALVES} [[camshaft.valves]] tables")
    valves = []
    for t in rows:
        name, train = _train_path(t, folder)
        offset = t.number("phase", unit="cam deg", default=0.0, min_value=-720.0, max_value=720.0)
        cylinder = t.integer("cylinder", min_value=1, max_value=cylinders) if t.has("cylinder") else None
        phase = offset + (0.0 if cylinder is None else phases[cylinder])
        default = f"{train.stem}" + ("" if cylinder is None else f" cyl {cylinder}")
        valves.append(ValveSpec(t.string("label", default=default), name, train, phase, cylinder, offset))
        t.finish()
    shaft.finish()
    top.finish()
    return CamshaftSpec(title, rpm, tuple(valves), cylinders, order)


def dump(spec: CamshaftSpec) -> dict[str, Any]:
    """The document :func:`load` reads back to ``spec``."""
    valves = []
    for v in spec.valves:
        row: dict[str, Any] = {"train": v.train}
        if v.cylinder is not None:
            row["cylinder"] = v.cylinder
        row |= {"phase": v.offset_deg, "label": v.label}
        valves.append(row)
    shaft: dict[str, Any] = {"cylinders": spec.cylinders, "firing_order": list(spec.firing_order)}
    if spec.rpm is not None:
        shaft["rpm"] = spec.rpm
    return {"kind": spec.kind, "title": spec.title, "camshaft": shaft | {"valves": valves}}


def with_overrides(doc: dict[str, Any], overrides: dict[str, Any]) -> dict[str, Any]:
    """The document with ``vtool solve``'s field flags set (``--rpm``: ``camshaft.rpm``), for :func:`load`."""
    from vtool.presets.paths import set_fields

    if not isinstance(doc.get("camshaft"), dict):
        return doc  # the loader says what is missing
    return set_fields(doc, overrides)


def load_camshaft(name_or_path: str | os.PathLike[str]) -> CamshaftSpec:
    """A camshaft preset (a path or a shipped name); another kind of preset is refused in one line."""
    from vtool.presets import load_preset
    from vtool.presets.kinds import require_kind

    spec = load_preset(name_or_path)
    require_kind(spec, "camshaft", "a camshaft")
    return spec


def train_spec(path: Path, rpm: float | None) -> Any:
    """A valve's train spec at the camshaft's speed, checked for what the torque needs."""
    from vtool.presets import load_preset
    from vtool.presets.kinds import require_kind

    spec = load_preset(path)
    require_kind(spec, "valvetrain", "a camshaft's valve", field=f"train {path.stem}")
    if spec.follower is None:
        raise InputError(f"train {path.stem}", "no [follower]", "a train with a follower (a train type or "
                         "[follower]: the torque needs the contact geometry)")
    if rpm is not None:
        spec = dataclasses.replace(spec, run=dataclasses.replace(spec.run, rpm=rpm))
    if spec.run.degrees < 360.0:
        raise InputError(f"train {path.stem}: run.degrees", spec.run.degrees, ">= 360 (a whole revolution)", "deg")
    return spec


def solve(camshaft: CamshaftSpec, progress: Callable[[float], None] | None = None,
          cancel: Callable[[], bool] | None = None, max_steps: float | None = None) -> Any:
    """Run each distinct train once and sum the valves' torques (:func:`vtool.solvers.studies.camshaft.sum_valves`).

    ``progress(fraction)`` and ``cancel()`` are handed to each train's run (the TUI's worker); a cancelled run
    returns None. ``max_steps``: each train's cost limit (``vtool solve --max-steps``; default the back end's)."""
    from vtool.solvers.run import simulate
    from vtool.solvers.studies.camshaft import sum_valves
    from vtool.solvers.studies.torque import last_revolution, row_unit, torque_rows

    runs: dict[Path, tuple[Any, Any]] = {}
    units = set()
    trains = list(dict.fromkeys(v.path for v in camshaft.valves))
    for k, path in enumerate(trains):
        spec = train_spec(path, camshaft.rpm)
        units.add(spec.units)
        share = None if progress is None else (lambda f, k=k: progress((k + f) / len(trains)))
        trace = simulate(spec, progress=share, cancel=cancel, max_steps=max_steps)
        if cancel is not None and cancel():
            return None
        window = last_revolution(trace.cam_angle)
        if window is None:
            raise InputError(f"train {path.stem}: run.degrees", spec.run.degrees, ">= 360", "deg")
        rows = torque_rows(spec, trace.cam_angle, trace.contact_force[:, trace.cam_clearance_index()])
        keep = (rows.cam_angle_deg >= window[0] - 1e-9) & (rows.cam_angle_deg < window[0] + 360.0 - 1e-9)
        runs[path] = (spec, (rows.cam_angle_deg[keep] - window[0], rows.torque[keep]))
    if len(units) > 1:
        raise InputError("camshaft.valves", sorted(units), "trains in one unit system")
    first = runs[camshaft.valves[0].path][0]
    step = min(spec.run.output_interval for spec, _ in runs.values())
    return sum_valves([v.label for v in camshaft.valves], [runs[v.path][1] for v in camshaft.valves],
                      [v.phase_deg for v in camshaft.valves], step, row_unit(first, "torque"), first.run.rpm)


CAM_ANGLE = "camshaft angle (deg)"


def camshaft_chart(title: str, result: Any, valves: bool = True) -> Any:
    """The summed drive torque against camshaft angle and, below it, each valve's share (distinct lobes
    once: valves of one phase and train draw one curve)."""
    from vtool.chart import Chart, Panel, curve, with_unit

    u = result.unit
    s = result.summary()
    total = Panel((curve(f"sum of {len(result.valves)} valves (mean {s['mean_torque']:.4g} {u}, "
                         f"peak-to-peak {s['peak_to_peak_torque']:.4g} {u})", result.cam_angle_deg, result.torque),),
                  with_unit("camshaft torque", u))
    panels = [total]
    if valves:
        seen: dict[tuple[float, bytes], str] = {}
        for label, phase, share in zip(result.valves, result.phases_deg, result.valve_torque, strict=True):
            seen.setdefault((round(float(phase), 6), share.tobytes()), label)
        shares = tuple(curve(f"{label} ({phase:g} deg)", result.cam_angle_deg, result.valve_torque[i])
                       for i, (label, phase) in enumerate(zip(result.valves, result.phases_deg, strict=True))
                       if label in seen.values())
        panels.append(Panel(shares, with_unit("valve torque", u)))
    return Chart(f"camshaft drive torque ({u}) at {result.rpm:g} cam rev/min", CAM_ANGLE, tuple(panels), title)


def train_torque_chart(trace: Any) -> Any:
    """One train's cam drive torque over the run against cam angle, and the cam's normal contact force."""
    from vtool.chart import Chart, Panel, curve, with_unit
    from vtool.solvers.studies.torque import row_unit, torque_rows

    spec = trace.spec
    rows = torque_rows(spec, trace.cam_angle, trace.contact_force[:, trace.cam_clearance_index()])
    u = row_unit(spec, "torque")
    return Chart(f"cam drive torque ({u})", "cam angle (deg)",
                 (Panel((curve("drive torque", rows.cam_angle_deg, rows.torque),), with_unit("cam torque", u)),
                  Panel((curve("normal force", rows.cam_angle_deg, rows.normal_force),),
                        with_unit("cam normal force", spec.unit_system.force))), spec.title)
