"""``vtool modes PRESET``: natural frequencies and mode shapes per contact layer."""

from __future__ import annotations

import math

import click

from vtool.errors import RunError
from vtool.files import json_text


@click.command()
@click.argument("preset")
@click.option("--json", "as_json", is_flag=True, help="Print the same as JSON.")
def modes(preset: str, as_json: bool) -> None:
    """Natural frequencies (rad/s, Hz) and mass-normalised mode shapes of every
    contact layer, with the static start (cam offset XZERO, follower force FZERO)."""
    from vtool.presets import load_preset
    from vtool.presets.kinds import require_kind
    from vtool.solvers.model.assembly import surge_labels
    from vtool.solvers.model.mechanism import assemble
    from vtool.solvers.run import NUMERICAL_FAILURES

    spec = load_preset(preset)
    require_kind(spec, "valvetrain", "`vtool modes`")
    try:
        mechanism = assemble(spec)
    except NUMERICAL_FAILURES as exc:
        raise RunError(f"assembling the mechanism failed ({type(exc).__name__}); check the members' "
                       "sections, moduli and masses") from None
    units = spec.unit_system
    report = {
        "preset": preset,
        "title": spec.title,
        "units": spec.units,
        "cam_offset_XZERO": {"value": mechanism.start.cam_offset, "unit": units.length},
        "follower_force_FZERO": {"value": mechanism.start.follower_force, "unit": units.force},
        "follower_stiffness": {"value": mechanism.start.follower_stiffness, "unit": units.stiffness},
        "layers": [],
    }
    for layer in mechanism.all_layers():
        report["layers"].append(
            {
                "closed": sorted(layer.closed),
                "coordinates": [f"q{k}" for k in layer.kept],
                "omega_rad_s": layer.modes.omega.tolist(),
                "frequency_hz": (layer.modes.omega / (2 * math.pi)).tolist(),
                "damping_ratio": [
                    0.0 if w == 0.0 else z for w, z in zip(layer.modes.omega, layer.damping_ratios, strict=True)
                ],
                "mode_shapes_columns": layer.modes.shapes.tolist(),
                "surge": surge_labels(spec, layer.T @ layer.modes.shapes),
            }
        )
    if spec.springs:
        from vtool.solvers.model.spring import surge_table

        report["spring_surge"] = surge_table(spec.springs, spec.run.rpm)
    if spec.seat is not None:
        from vtool.solvers.model.lash import lash_of

        report["seat_position"] = {"value": spec.seat.position, "unit": units.length}
        report["lash"] = {"value": lash_of(spec), "unit": units.length}
    if as_json:
        click.echo(json_text(report))
        return
    click.echo(f"{spec.title}  [{spec.units}]")
    click.echo(f"cam offset XZERO   = {mechanism.start.cam_offset:.8f} {units.length}")
    click.echo(f"follower force FZERO = {mechanism.start.follower_force:.8g} {units.force}")
    if spec.seat is not None:
        click.echo(f"seat position      = {spec.seat.position:.8g} {units.length}, "
                   f"lash {report['lash']['value']:.6g} {units.length} (follower clearance on the base circle)")
    if spec.springs:
        from vtool.solvers.model.spring import surge_text

        for line in surge_text(report["spring_surge"], units):
            click.echo(line)
    for layer, entry in zip(mechanism.all_layers(), report["layers"], strict=True):
        click.echo("")
        click.echo(f"Layer {layer.label()}  ({layer.size} coordinates)")
        click.echo(f"  {'mode':>4} {'omega (rad/s)':>14} {'f (Hz)':>12} {'zeta':>6}  kind")
        for i, (w, f, z, kind) in enumerate(
            zip(entry["omega_rad_s"], entry["frequency_hz"], entry["damping_ratio"], entry["surge"], strict=True),
            start=1,
        ):
            click.echo(f"  {i:>4} {w:>14.6g} {f:>12.6g} {z:>6.3g}  {kind}".rstrip())
        click.echo("  mode shapes (mass-normalised, columns = modes):")
        header = "".join(f"{i:>11}" for i in range(1, layer.size + 1))
        click.echo(f"  {'':>4}{header}")
        import numpy as np  # here, not at import: `vtool --help` loads no numpy

        shapes = layer.modes.shapes
        shown = np.where(np.abs(shapes) < 1e-9 * np.abs(shapes).max(axis=0), 0.0, shapes)  # round-off noise
        for row, k in enumerate(layer.kept):
            values = "".join(f"{v:>11.4g}" for v in shown[row])
            click.echo(f"  q{k:<3}{values}")
