"""``vtool size PRESET --rpm-max R``: elements per member and cam harmonics the speed range needs."""

from __future__ import annotations

import click


@click.command()
@click.argument("preset")
@click.option("--rpm-max", type=float, required=True, help="Top of the speed range (rev/min).")
@click.option("--tolerance", type=float, default=0.01, show_default=True,
              help="Relative change of peak forces and seating velocity that counts as converged.")
@click.option("--max-elements", type=int, default=8, show_default=True, help="Most elements tried per member.")
def size(preset: str, rpm_max: float, tolerance: float, max_elements: int) -> None:
    """Size the model to the question: the highest cam harmonic that matters at
    RPM_MAX, and the elements per member (and Fourier harmonics of a table cam)
    beyond which refinement changes peak forces and seating velocity by less
    than the tolerance; every row is a measured run with its cost."""
    from vtool.errors import InputError
    from vtool.presets import load_preset
    from vtool.solvers.studies.size import size_study, study_text

    spec = load_preset(preset)
    from vtool.presets.kinds import require_kind

    require_kind(spec, "valvetrain", "`vtool size`")
    if not 1e-3 <= rpm_max <= 1e6:  # the range of run.rpm (presets.valvetrain.check_run_value)
        raise InputError("--rpm-max", rpm_max, ">= 0.001 and <= 1e6", "rev/min")
    if not 0 < tolerance < 1:
        raise InputError("--tolerance", tolerance, "> 0 and < 1 (a fraction)")
    if not 1 <= max_elements <= 64:
        raise InputError("--max-elements", max_elements, "an integer in 1..64")
    study = size_study(spec, rpm_max, tolerance, max_elements,
                       progress=lambda run: click.echo(f"size: running {run}", err=True))
    click.echo(study_text(study, spec.title))
