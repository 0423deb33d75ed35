"""The one table of preset kinds: what each ``kind`` loads into and who runs and shows it.

Every place that dispatches on a preset's kind reads :data:`KINDS` and
nothing else: the loader (:func:`vtool.presets.load_preset`,
:func:`~vtool.presets.load_document`, :func:`~vtool.presets.save_spec`),
``vtool solve`` (which flags apply, which function runs and prints), every
command that takes one kind only (:func:`require_kind`) and the TUI (which
screen opens a preset, which loader a screen's form uses). The entries name
code by dotted path strings (``module:attribute`` or a module), so this table
imports nothing: the presets layer never imports ``app/``, and the CLI
imports only the module of the kind it runs
(``tests/test_dispatch.py`` checks that no other module compares a kind).

==========  ================================================  ========================  ========================================  ========================
kind        spec type                                         loader (``load/dump``)    solve (``vtool solve``: runs and prints)  TUI screen module
==========  ================================================  ========================  ========================================  ========================
valvetrain  vtool.solvers.model.spec:MechanismSpec            vtool.presets.valvetrain  vtool.app.cli.solve:run_valvetrain        vtool.app.tui.valvetrain
boom_wall   vtool.assessments.sonic_boom.spec:BoomWallSpec    vtool.presets.boom        vtool.app.cli.boom:solve_preset           vtool.app.tui.boom
boom_floor  vtool.assessments.sonic_boom.spec:BoomFloorSpec   vtool.presets.boom        vtool.app.cli.boom:solve_preset           vtool.app.tui.boom
plate       vtool.presets.plate:PlateSpec                     vtool.presets.plate       vtool.app.cli.plate:solve_preset          vtool.app.tui.plate
camshaft    vtool.presets.camshaft:CamshaftSpec               vtool.presets.camshaft    vtool.app.cli.camshaft:solve_preset       vtool.app.tui.camshaft
==========  ================================================  ========================  ========================================  ========================

A loader module has ``load(doc, folder=None) -> spec`` (``folder``: the
preset's folder, against which a file it names is found: a cam lift table,
a boom pulse CSV) and ``dump(spec) -> doc``. A solve function has
``solve(spec, csv_path, plot, as_json, figure=None, **flags)``, where
``flags`` are the kind's :attr:`Kind.run_options` that are not preset
fields, as keyword arguments (``--every-step`` is ``every_step``); those
that are preset fields (:attr:`Kind.overrides`: ``--rpm`` is ``run.rpm``)
are set into the document and checked by the loader (the loader module then
has ``with_overrides(doc, {path: value}) -> doc``). ``vtool solve`` refuses
any other flag for the kind. A TUI screen module has ``SCREEN``, its
:class:`~vtool.app.tui.base.DomainScreen` class; one screen may show
several kinds (the boom screen: walls and floors). A ``camshaft`` preset runs
several valvetrain presets (:mod:`vtool.presets.camshaft`); ``vtool camshaft`` is
its ``vtool solve`` under the command's older name. The table above is the
data below (``tests/test_dispatch.py`` compares them).
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Any

from vtool.errors import InputError


@dataclass(frozen=True)
class Kind:
    """One preset kind (see the module table). Paths are ``module:attribute`` or a module."""

    name: str
    description: str
    spec_type: str
    loader: str
    solve: str
    screen: str
    #: the flags of ``vtool solve`` that apply to this kind beyond --csv/--plot/--json
    run_options: tuple[str, ...] = ()
    #: those of them that are preset fields: flag -> field path, set into the document before the load
    #: (:class:`vtool.presets.Override`), so the loader checks them once, as the file's own values
    overrides: tuple[tuple[str, str], ...] = ()
    #: ``vtool report``'s content: ``report(spec, *, preset, sweep, metric, workers, ...) -> Report``
    report: str = ""


KINDS: dict[str, Kind] = {
    "valvetrain": Kind("valvetrain", "valve-train dynamics (Gnilka 1971)",
                       "vtool.solvers.model.spec:MechanismSpec", "vtool.presets.valvetrain",
                       "vtool.app.cli.solve:run_valvetrain", "vtool.app.tui.valvetrain",
                       ("--backend", "--dt", "--rpm", "--degrees", "--every-step", "--events",
                        "--max-steps", "--impact", "--start", "--orders", "--format"),
                       (("--backend", "run.backend"), ("--dt", "run.time_step"), ("--rpm", "run.rpm"),
                        ("--degrees", "run.degrees"), ("--impact", "contact.impact"),
                        ("--start", "initial.velocities")), "vtool.presets.report:valvetrain_report"),
    "boom_wall": Kind("boom_wall", "sonic-boom wall assessment",
                      "vtool.assessments.sonic_boom.spec:BoomWallSpec", "vtool.presets.boom",
                      "vtool.app.cli.boom:solve_preset", "vtool.app.tui.boom",
                      report="vtool.presets.report:boom_report"),
    "boom_floor": Kind("boom_floor", "sonic-boom floor assessment",
                       "vtool.assessments.sonic_boom.spec:BoomFloorSpec", "vtool.presets.boom",
                       "vtool.app.cli.boom:solve_preset", "vtool.app.tui.boom",
                      report="vtool.presets.report:boom_report"),
    "plate": Kind("plate", "condensed-plate study", "vtool.presets.plate:PlateSpec",
                  "vtool.presets.plate", "vtool.app.cli.plate:solve_preset", "vtool.app.tui.plate",
                  report="vtool.presets.report:plate_report"),
    "camshaft": Kind("camshaft", "several valve trains on one camshaft: summed drive torque",
                     "vtool.presets.camshaft:CamshaftSpec", "vtool.presets.camshaft",
                     "vtool.app.cli.camshaft:solve_preset", "vtool.app.tui.camshaft",
                     ("--rpm", "--max-steps"), (("--rpm", "camshaft.rpm"),)),
}


def resolve(path: str) -> Any:
    """The object at a dotted path ``module:attribute`` (or the module itself)."""
    module, _, attribute = path.partition(":")
    loaded = importlib.import_module(module)
    return getattr(loaded, attribute) if attribute else loaded


def kind_named(name: Any, field: str = "kind") -> Kind:
    """The :class:`Kind` called ``name``; an unknown name is an InputError listing the kinds."""
    if not isinstance(name, str) or name not in KINDS:
        raise InputError(field, name, f"one of: {', '.join(KINDS)}")
    return KINDS[name]


def require_kind(spec: Any, wanted: str | tuple[str, ...], what: str, field: str = "preset") -> None:
    """The one wrong-kind check: ``spec`` must be of kind ``wanted`` for ``what`` (e.g. `vtool modes`)."""
    allowed = (wanted,) if isinstance(wanted, str) else wanted
    kind = getattr(spec, "kind", None)
    if kind not in allowed:
        raise InputError(field, kind, f"a {' or '.join(allowed)} preset for {what}")
