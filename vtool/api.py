"""The Python API: vtool for scripts and notebooks (``import vtool``; docs/api.md).

Five calls cover the work the CLI does, on the same code path
(load preset -> assemble -> simulate -> metrics):

>>> import vtool
>>> model = vtool.load("gnilka-1a")                       # a shipped name, a path, or a dict
>>> model = model.set({"run.rpm": 9000, "run.degrees": 400})   # dotted paths, as `vtool sweep --set`
>>> result = model.solve(backend="newmark")
>>> arrays = result.arrays()                              # {"time (s)": ndarray, ...}, units in the names
>>> study = model.sweep({"run.rpm": [8000, 10000]}, workers=1)
>>> model.find_speed("jump-speed", scan=range(6000, 12001, 2000)).speed   # rev/min

Every value is validated by the preset loader, and bad input raises
:class:`vtool.errors.InputError` with the CLI's one-line message; a failed
run raises :class:`vtool.errors.RunError`. Results are NumPy arrays; a
pandas DataFrame comes from ``to_dataframe()`` when pandas is installed (it
is not a dependency). Figures and reports are the CLI's (matplotlib).

Layering: this module sits at the top beside ``vtool.app`` (it may use the
app's figure and report writers); nothing below imports it. ``import vtool``
does not load it: ``vtool/__init__.py`` resolves ``vtool.load`` and the other
names on first use (PEP 562), so ``import vtool.errors`` stays light.
"""

from __future__ import annotations

import copy
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vtool.errors import InputError

__all__ = ["Model", "Result", "SweepResult", "load", "preset_names"]


def preset_names() -> list[str]:
    """The shipped preset names (any kind)."""
    from vtool.presets import shipped_names

    return shipped_names()


def load(preset: str | os.PathLike[str] | Mapping[str, Any]) -> Model:
    """A model from a shipped preset name, a preset file, or a preset document (a dict as the TOML reads).

    >>> vtool.load({"kind": "valvetrain", ...})  # doctest: +SKIP
    """
    from vtool.presets import find_preset, read_document

    if isinstance(preset, Mapping):
        return Model(copy.deepcopy(dict(preset)), None)
    path = find_preset(preset)
    return Model(read_document(path), path.parent)


def _dataframe(columns: Mapping[str, np.ndarray]) -> Any:
    try:
        import pandas
    except ImportError:
        raise ImportError("to_dataframe needs pandas (pip install pandas); arrays() gives the same columns "
                          "as NumPy arrays") from None
    return pandas.DataFrame(dict(columns))


@dataclass(frozen=True)
class Model:
    """A validated preset: its document (``document``), its spec (``spec``) and where it came from."""

    document: dict[str, Any]
    folder: Path | None = None  # resolves a cam lift_table file named relative to the preset
    spec: Any = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "spec", self._load(self.document))

    def _load(self, document: dict[str, Any]) -> Any:
        from vtool.presets import load_document

        return load_document(document, self.folder)

    @property
    def title(self) -> str:
        return str(self.spec.title)

    @property
    def kind(self) -> str:
        return str(self.spec.kind)

    def get(self, path: str) -> Any:
        """One field of the document by its dotted path (``members.valve_spring.stiffness``)."""
        from vtool.presets.paths import get_field

        return get_field(self.document, path)

    def set(self, fields: Mapping[str, Any] | None = None, **run: Any) -> Model:
        """A new model with fields changed: ``{"dotted.path": value}`` and/or [run] keys as keywords
        (``rpm=9000``); validated like a preset (one-line InputError)."""
        from vtool.presets.paths import set_fields

        changes = dict(fields or {}) | {f"run.{key}": value for key, value in run.items()}
        document = set_fields(self.document, changes)
        if "run.rpm" in changes and self._takes("--rpm") and isinstance(document.get("title"), str):
            from vtool.presets.valvetrain import rpm_title

            try:  # the title names the new speed, as `vtool solve --rpm` does; a bad speed is the loader's
                document["title"] = rpm_title(document["title"], float(changes["run.rpm"]))
            except (TypeError, ValueError):
                pass
        return Model(document, self.folder)

    def solve(self, backend: str | None = None, *, every_step: bool = False, **run: Any) -> Result:
        """Run the valve train (``backend``: newmark, exact, scipy; ``run``: [run] keys such as degrees)."""
        self._require_valvetrain("solve")
        from vtool.solvers.run import simulate

        model = self.set(**run) if run else self
        spec = model.spec
        if backend is not None:
            from vtool.presets.valvetrain import with_run_overrides
            from vtool.solvers.backends import available

            if backend not in available():
                raise InputError("backend", backend, f"one of: {', '.join(available())}")
            spec = with_run_overrides(spec, backend=backend)
        return Result(simulate(spec, every_step=every_step))

    def sweep(self, fields: Mapping[str, Iterable[Any]], *, workers: int | None = 1,
              every_step: bool = False) -> SweepResult:
        """Run a grid over ``{"dotted.path": values}`` (values checked first as `vtool sweep` does) and return the metrics
        of every point (docs/sweep.md defines them)."""
        self._require_valvetrain("sweep")
        from vtool.presets.paths import plan_document
        from vtool.solvers.studies.metrics import metric_columns
        from vtool.solvers.studies.sweep import make_runner, run_points

        if not fields:
            raise InputError("fields", "{}", "at least one {field path: values}")
        plan = plan_document(self.document, [(path, list(values)) for path, values in fields.items()],
                             folder=self.folder)
        runner = make_runner(workers)
        try:
            outcome = run_points(plan.points, runner, every_step=every_step)
        finally:
            runner.close()
        return SweepResult(plan.fields, tuple(metric_columns(plan.spec)), tuple(outcome.results))

    def find_speed(self, criterion: str = "jump-speed", scan: Iterable[float] = range(1000, 20001, 1000), *,
                   tolerance: float = 1.0, workers: int | None = 1) -> Any:
        """The lowest cam speed (rev/min, to ``tolerance``) where the follower leaves the cam (``jump-speed``)
        or the valve bounces (``bounce-speed``): ``vtool sweep --find``. Returns a
        :class:`vtool.solvers.studies.sweep.SpeedResult` (``speed``, ``history``, ``message``)."""
        self._require_valvetrain("find_speed")
        from vtool.solvers.studies.sweep import find_speed, make_runner

        runner = make_runner(workers)
        try:
            return find_speed(criterion, lambda rpm: self.set(rpm=rpm).spec, list(scan), runner,
                              tolerance=tolerance)
        finally:
            runner.close()

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the model as a preset TOML (atomically)."""
        from vtool.presets import save_spec

        save_spec(self.spec, path)

    def _takes(self, flag: str) -> bool:
        """Whether this preset's kind takes a run flag (the kinds table says: presets/kinds.py)."""
        from vtool.presets.kinds import KINDS

        return flag in KINDS[self.kind].run_options

    def _require_valvetrain(self, what: str) -> None:
        from vtool.presets.kinds import require_kind

        require_kind(self.spec, "valvetrain", what)


@dataclass(frozen=True)
class Result:
    """One run: its :class:`vtool.solvers.trace.Trace` (``trace``) and NumPy views of it."""

    trace: Any

    @property
    def spec(self) -> Any:
        return self.trace.spec

    @property
    def time(self) -> np.ndarray:
        """Time of each output row (s)."""
        return np.asarray(self.trace.time)

    @property
    def cam_angle(self) -> np.ndarray:
        """Cam angle of each output row (deg)."""
        return np.asarray(self.trace.cam_angle)

    def quantity(self, expression: str) -> np.ndarray:
        """``q7``, ``q1-q9``, ``F2`` (the preset's quantity names) on every output row."""
        return np.asarray(self.trace.quantity(expression))

    def contact_force(self, clearance: str) -> np.ndarray:
        """The contact force at a clearance, by its name (``cam``) or force label (``F1``)."""
        try:
            return np.asarray(self.trace.force(clearance))
        except KeyError:
            names = [c.name for c in self.spec.clearances]
            raise InputError("clearance", clearance, f"one of: {', '.join(names)} (or F<n>)") from None

    def arrays(self) -> dict[str, np.ndarray]:
        """Every CSV column as an array, named as in the CSV header (units included), then the
        configuration masks. A column is given once: the CSV repeats a listed quantity that is also a
        coordinate (1A lists q9 and F1 again); the dict keeps the first."""
        names, columns = self.trace.csv_columns(self.spec.run.quantities)
        rows = slice(None)
        arrays = {name: np.asarray(column(rows)) for name, column in zip(names, columns, strict=False)}
        arrays["configuration"] = np.asarray(self.trace.configuration)
        return arrays

    def to_dataframe(self) -> Any:
        """The :meth:`arrays` as a pandas DataFrame (needs pandas)."""
        return _dataframe(self.arrays())

    @property
    def events(self) -> list[dict[str, Any]]:
        """The event list (time, cam angle, clearance, kind, relative velocity, configurations)."""
        return list(self.trace.summary()["events_list"])

    def summary(self) -> dict[str, Any]:
        """What ``vtool solve --json`` prints."""
        return dict(self.trace.summary())

    def metrics(self) -> dict[str, float]:
        """The run's metrics, as a sweep reports them (docs/sweep.md)."""
        from vtool.solvers.studies.metrics import run_metrics

        return run_metrics(self.trace)

    def save_figure(self, path: str | os.PathLike[str]) -> Path:
        """Forces, displacements and configuration as a PNG, SVG or PDF figure (``vtool solve --figure``)."""
        from vtool.app.figures import save_figure
        from vtool.presets.charts import trace_charts

        return save_figure(trace_charts(self.trace), Path(path), "path")

    def save_report(self, path: str | os.PathLike[str]) -> Path:
        """The run's report, .pdf or .html (``vtool report`` without a sweep)."""
        from vtool.app.report import write_report
        from vtool.presets.report import report_of_trace

        return write_report(report_of_trace(self.trace), Path(path), "path")


@dataclass(frozen=True)
class SweepResult:
    """The points of a sweep: swept values and metrics, as arrays."""

    fields: tuple[tuple[str, str], ...]  # (path, unit) of each swept field
    metric_units: tuple[tuple[str, str], ...]  # (metric, unit)
    points: tuple[Any, ...]  # vtool.solvers.studies.sweep.PointResult, in grid order

    def __len__(self) -> int:
        return len(self.points)

    def values(self, path: str) -> np.ndarray:
        """The swept values of one field, point by point."""
        return np.asarray([dict(p.values)[path] for p in self.points])

    def metric(self, name: str) -> np.ndarray:
        """One metric, point by point (NaN where a point failed)."""
        if name not in dict(self.metric_units):
            raise InputError("metric", name, f"one of: {', '.join(n for n, _ in self.metric_units)}")
        return np.asarray([p.metrics.get(name, np.nan) for p in self.points], dtype=float)

    @property
    def status(self) -> list[str]:
        return [p.status for p in self.points]

    def arrays(self) -> dict[str, np.ndarray]:
        """Swept fields, then metrics, named with their units (as the sweep CSV's header)."""
        from vtool.solvers.studies.sweep import column_title

        columns = {column_title(path, unit): self.values(path) for path, unit in self.fields}
        columns |= {column_title(name, unit): self.metric(name) for name, unit in self.metric_units}
        columns["status"] = np.asarray(self.status)
        return columns

    def to_dataframe(self) -> Any:
        """The :meth:`arrays` as a pandas DataFrame (needs pandas)."""
        return _dataframe(self.arrays())
