"""One path for a setting (issue 36): a flag is a preset field the loader checks once, as the file's value;
ω is computed in one place; the beta/gamma rule is stated once."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from vtool.app.cli.main import cli
from vtool.errors import InputError
from vtool.presets import PRESET_DIR, Override, load_preset
from vtool.presets.kinds import KINDS
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.model.spec import BETA_RANGE, GAMMA_RANGE
from vtool.solvers.newmark.backend import NewmarkBackend, NewmarkOptions
from vtool.units import cam_speed

ROOT = Path(__file__).resolve().parent.parent
BAD = {"run.rpm": -1.0, "run.time_step": 0.5, "run.degrees": 0.0, "run.backend": "euler",
       "contact.impact": "elastic", "initial.velocities": "random"}


def in_file(tmp_path: Path, path: str, value: object) -> Path:
    """gnilka-1a with ``path`` set to ``value`` in its text (the key is in the shipped file)."""
    table, _, key = path.partition(".")
    text = (PRESET_DIR / "gnilka-1a.toml").read_text(encoding="utf-8")
    section = text.index(f"[{table}]")
    line = re.compile(rf"^{key} = .*$", re.MULTILINE).search(text, section)
    assert line is not None, path
    written = f'"{value}"' if isinstance(value, str) else repr(value)
    out = tmp_path / "changed.toml"
    out.write_text(text[:line.start()] + f"{key} = {written}" + text[line.end():], encoding="utf-8")
    return out


@pytest.mark.parametrize("flag, path", KINDS["valvetrain"].overrides)
def test_a_flag_is_refused_by_the_loader_as_the_same_value_in_the_file(tmp_path: Path, flag: str, path: str) -> None:
    value = BAD[path]
    with pytest.raises(InputError) as from_file:
        load_preset(in_file(tmp_path, path, value))
    with pytest.raises(InputError) as from_flag:
        load_preset("gnilka-1a", (Override(path, value, flag),))
    assert from_file.value.field == path and from_flag.value.field == flag
    assert (from_flag.value.expected, from_flag.value.unit) == (from_file.value.expected, from_file.value.unit)
    if path != "run.backend":  # (click refuses an unknown back end by its choices, before any load)
        result = CliRunner().invoke(cli, ["solve", "gnilka-1a", flag, str(value)])
        assert result.exit_code == 2 and result.output.startswith(f"error: {flag}: got "), result.output
        assert from_file.value.expected in result.output


def test_a_flag_that_is_valid_reaches_the_spec_through_the_loader() -> None:
    spec = load_preset("gnilka-1a", (Override("run.rpm", 9000.0, "--rpm"), Override("run.time_step", 2e-6, "--dt"),
                                     Override("contact.impact", "momentum", "--impact")))
    assert (spec.run.rpm, spec.run.time_step, spec.contact.impact) == (9000.0, 2e-6, "momentum")
    assert all(c.impact is None for c in spec.clearances)  # the mechanism's law for every clearance
    assert "9,000 RPM (override)" in spec.title


def test_omega_is_computed_in_one_place() -> None:
    spec = load_preset("gnilka-1a")
    assert spec.run.omega == cam_speed(spec.run.rpm) == assemble(spec).omega
    assert cam_speed(30.0) == pytest.approx(3.141592653589793)
    conversions = re.compile(r"rpm[^\n]*\*[^\n]*(pi|/ *30|/ *60)|pi */ *30")
    found = [f"{path.relative_to(ROOT)}:{number}" for folder in ("app", "presets", "solvers", "assessments", "vtool")
             for path in (ROOT / folder).rglob("*.py") if path.name != "units.py"
             for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
             if conversions.search(line.split("#")[0]) and '"""' not in line]
    assert found == [], f"rpm -> rad/s outside vtool.units.cam_speed: {found}"


@pytest.mark.parametrize("key, value", [("beta", 0.6), ("beta", 0.0), ("gamma", 0.4), ("gamma", 1.2)])
def test_the_beta_gamma_rule_is_stated_once(key: str, value: float) -> None:
    low, high = BETA_RANGE if key == "beta" else GAMMA_RANGE
    with pytest.raises(InputError) as loaded:  # the loader's [run] reader (a study's with_run_overrides)
        _load_with_run("gnilka-1a", key, value)
    mechanism = assemble(load_preset("gnilka-1a"))
    options = NewmarkOptions(1e-6, **{key: value})
    with pytest.raises(InputError) as checked:
        NewmarkBackend().check(mechanism, options)
    assert loaded.value.field == checked.value.field == f"run.{key}"
    assert loaded.value.expected == checked.value.expected
    assert f"{low:g}" in checked.value.expected and f"{high:g}" in checked.value.expected


def _load_with_run(name: str, key: str, value: float) -> object:
    from vtool.presets.valvetrain import with_run_overrides

    return with_run_overrides(load_preset(name), **{key: value})
