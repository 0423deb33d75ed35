"""Camshaft presets: several valve trains on one camshaft (``vtool camshaft PRESET``).

A camshaft preset names its valves' train presets and their phases::

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

Each distinct train (preset and speed) is run once
(:func:`vtool.solvers.run.simulate`); its drive torque over its last whole
revolution (:mod:`vtool.solvers.studies.torque`) is shifted by each valve's
phase and summed (:mod:`vtool.solvers.studies.camshaft`). Every train must
have a ``[follower]`` (a train type gives one): the torque needs the contact
geometry, and all trains share the camshaft's unit system.

Camshaft presets live in ``presets/camshafts/`` (they are not a preset
``kind`` of :mod:`vtool.presets.kinds`: they run several valvetrain presets
and have no screen of their own).
"""

from __future__ import annotations

import dataclasses
import os
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from vtool.errors import InputError
from vtool.presets.fields import Table

CAMSHAFT_DIR = Path(__file__).resolve().parent / "camshafts"
MAX_VALVES = 64


@dataclass(frozen=True)
class ValveSpec:
    label: str
    train: Path
    phase_deg: float


@dataclass(frozen=True)
class CamshaftSpec:
    title: str
    rpm: float | None
    valves: tuple[ValveSpec, ...]


def find_camshaft(name_or_path: str | os.PathLike[str]) -> Path:
    """A camshaft preset given as a path or a shipped name (``presets/camshafts/NAME.toml``)."""
    candidate = Path(name_or_path)
    if candidate.is_file():
        return candidate
    shipped = CAMSHAFT_DIR / f"{candidate.stem}.toml"
    if candidate.parent == Path(".") and candidate.suffix in ("", ".toml") and shipped.is_file():
        return shipped
    names = ", ".join(sorted(p.stem for p in CAMSHAFT_DIR.glob("*.toml")))
    raise InputError("preset", str(name_or_path), f"a camshaft preset file or one of: {names}")


def _train_path(t: Table, folder: Path) -> Path:
    from vtool.presets import find_preset

    name = t.string("train")
    beside = folder / name
    if beside.is_file():
        return beside
    try:
        return find_preset(name)
    except InputError:
        raise InputError(t.field("train"), name, "a shipped valvetrain preset or a file beside the camshaft "
                         "preset") from None


def load(doc: dict[str, Any], folder: Path) -> CamshaftSpec:
    """Validate a camshaft document (module doc)."""
    from vtool.solvers.studies.camshaft import cylinder_phases

    top = Table(doc, "")
    title = top.string("title", default="camshaft")
    shaft = top.table("camshaft")
    assert shaft is not None
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
        train = _train_path(t, folder)
        offset = t.number("phase", unit="cam deg", default=0.0, min_value=-720.0, max_value=720.0)
        cylinder = t.integer("cylinder", min_value=1, max_value=cylinders) if t.has("cylinder") else None
        phase = offset + (0.0 if cylinder is None else phases[cylinder])
        default = f"{train.stem}" + ("" if cylinder is None else f" cyl {cylinder}")
        valves.append(ValveSpec(t.string("label", default=default), train, phase))
        t.finish()
    shaft.finish()
    top.finish()
    return CamshaftSpec(title, rpm, tuple(valves))


def load_camshaft(name_or_path: str | os.PathLike[str]) -> CamshaftSpec:
    path = find_camshaft(name_or_path)
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError("preset", str(path), f"a readable TOML file ({exc})") from None
    return load(doc, path.parent)


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


def solve(camshaft: CamshaftSpec) -> Any:
    """Run each distinct train once and sum the valves' torques (:func:`vtool.solvers.studies.camshaft.sum_valves`)."""
    from vtool.solvers.run import simulate
    from vtool.solvers.studies.camshaft import sum_valves
    from vtool.solvers.studies.torque import last_revolution, row_unit, torque_rows

    runs: dict[Path, tuple[Any, Any]] = {}
    units = set()
    for valve in camshaft.valves:
        if valve.train in runs:
            continue
        spec = train_spec(valve.train, camshaft.rpm)
        units.add(spec.units)
        trace = simulate(spec)
        window = last_revolution(trace.cam_angle)
        if window is None:
            raise InputError(f"train {valve.train.stem}: run.degrees", spec.run.degrees, ">= 360", "deg")
        rows = torque_rows(spec, trace.cam_angle, trace.contact_force[:, trace.cam_clearance_index()])
        keep = (rows.cam_angle_deg >= window[0] - 1e-9) & (rows.cam_angle_deg < window[0] + 360.0 - 1e-9)
        runs[valve.train] = (spec, (rows.cam_angle_deg[keep] - window[0], rows.torque[keep]))
    if len(units) > 1:
        raise InputError("camshaft.valves", sorted(units), "trains in one unit system")
    first = runs[camshaft.valves[0].train][0]
    step = min(spec.run.output_interval for spec, _ in runs.values())
    return sum_valves([v.label for v in camshaft.valves], [runs[v.train][1] for v in camshaft.valves],
                      [v.phase_deg for v in camshaft.valves], step, row_unit(first, "torque"), first.run.rpm)
