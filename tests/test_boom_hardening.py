"""No input reaches a traceback or a hang: the fuzzer's boom reproducers (issue 14), one test each.

Every bad value is refused by the loader (or the cost guard) with a one-line
InputError before any numerics; numerical failures that slip past become a
RunError naming the quantity and the likely inputs.
"""

from __future__ import annotations

import copy
import time
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from vtool.app.cli.main import cli
from vtool.assessments.sonic_boom.assess import assess
from vtool.assessments.sonic_boom.pulses import idealized, read_pulse_csv
from vtool.assessments.sonic_boom.response import MAX_SAMPLES, peak_response, samples_estimate
from vtool.assessments.sonic_boom.spectra import EnvelopeSpec, envelope, ratio_grid
from vtool.assessments.sonic_boom.structures import flexural_rigidity, plate_omega, pseudo_height
from vtool.errors import InputError, RunError
from vtool.presets import PRESET_DIR, boom, read_document

WALL = read_document(PRESET_DIR / "boom-brick-wall.toml")
FLOOR = read_document(PRESET_DIR / "boom-tall-building.toml")


def _edit(doc: dict, path: tuple, value: object) -> dict:
    doc = copy.deepcopy(doc)
    target = doc
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    return doc


@pytest.mark.parametrize(("doc", "path", "value", "needle"), [
    (WALL, ("walls", 0, "thickness"), 1e-300, "walls[0].thickness: got 1e-300, expected >= 0.0394"),
    (WALL, ("walls", 0, "thickness"), 1e300, "walls[0].thickness: got 1e+300"),
    (WALL, ("walls", 0, "net_area"), 1e-300, "walls[0].net_area: got 1e-300"),
    (WALL, ("walls", 0, "poisson_ratio"), -0.999999, "expected >= -0.9 and <= 0.499"),
    (WALL, ("design", "f_max"), 1e6, "design.f_max: got 1000000.0, expected > 1 and <= 1000 Hz"),
    (WALL, ("boom", "positive_durations"), [1e300], "boom.positive_durations: got 1e+300"),
    (WALL, ("boom", "positive_durations"), [65.0], "expected a non-empty list of values in [0.0001, 10] s"),
    (WALL, ("boom", "positive_durations"), [0.1] * 10_000, "got 'a list of 10000 values', expected at most 100"),
    (WALL, ("criteria",), ["safe-limit"] * 10**5, "criteria: got 'a list of 100000 values'"),
    (WALL, ("boom", "envelope", "r1"), [0.0, 0.5, 0.001], "envelope: got '17535 pulses', expected at most 2000"),
    (WALL, ("boom", "envelope", "s"), [1.0, 2.0, 1e-300], "boom.envelope.s: got '[1, 2, 1e-300]'"),
    (FLOOR, ("floors", 0, "floor_weight"), 1.0, "top floor columns frequency: got '5230'"),
])
def test_loader_refuses_before_any_numerics(doc, path, value, needle) -> None:
    start = time.perf_counter()
    with pytest.raises(InputError) as err:
        assess(boom.load(_edit(doc, path, value)))
    assert needle in str(err.value)
    assert len(str(err.value)) < 300  # an echoed value is cut to a readable length
    assert time.perf_counter() - start < 5.0


def test_structure_formulas_raise_run_error_not_overflow() -> None:
    with pytest.raises(RunError, match="flexural rigidity D"):
        flexural_rigidity(1.5e6, 1e300, 0.15)
    with pytest.raises(RunError, match="plate frequency"):
        plate_omega(207.0, pseudo_height(1e-300, 207.0), 1e7, 1e-3)


def test_huge_ratio_and_grids_are_refused() -> None:
    with pytest.raises(InputError, match="tau/T"):
        peak_response(idealized("N"), 1e300)  # was OverflowError in _closed_form_roots
    with pytest.raises(InputError, match="range"):
        ratio_grid(0.0, 1e300, 1e-300)  # was OverflowError
    pulse = idealized("N")
    ratio = np.linspace(0, 1e4, 1000)
    assert samples_estimate(pulse, ratio) > MAX_SAMPLES
    with pytest.raises(InputError, match="samples"):
        peak_response(pulse, ratio)
    with pytest.raises(InputError, match="samples"):
        envelope(EnvelopeSpec(), np.linspace(0, 100, 2000))


def test_cancel_stops_an_envelope() -> None:
    from vtool.assessments.cancel import Cancelled

    calls = []

    def cancel() -> bool:
        calls.append(1)
        return len(calls) > 3

    with pytest.raises(Cancelled):
        envelope(EnvelopeSpec(), np.linspace(0, 2.5, 50), cancel=cancel)
    assert len(calls) == 4


def _run(*args: str):
    return CliRunner().invoke(cli, list(args))


def test_daf_csv_into_a_missing_folder_is_one_line() -> None:
    result = _run("boom", "daf", "--csv", "/missing/d.csv")
    assert result.exit_code == 2
    assert result.output.startswith("error: --csv: got '/missing/d.csv'")
    assert "Traceback" not in result.output and result.output.count("\n") == 1


def test_daf_range_overflow_is_one_line() -> None:
    result = _run("boom", "daf", "--range", "0:1e300:1e-300")
    assert result.exit_code == 2 and "range" in result.output and result.exception is None or \
        isinstance(result.exception, SystemExit)


def _csv_preset(tmp_path: Path, csv: str) -> Path:
    doc = _edit(WALL, ("boom",), {"positive_durations": [0.1], "pulse": "csv", "csv": csv})
    import tomli_w

    path = tmp_path / "wall.toml"
    path.write_text(tomli_w.dumps(doc))
    return path


def test_pulse_csv_never_echoes_a_foreign_file(tmp_path: Path) -> None:
    secret = tmp_path / "secret.txt"
    secret.write_text("root:x:0:0:root:/root:/bin/bash\ndaemon:x:1:1:daemon:/usr/sbin:/nologin\n")
    result = _run("boom", "wall", str(_csv_preset(tmp_path, str(secret))))
    assert result.exit_code == 2
    assert "root:x" not in result.output and "daemon" not in result.output
    assert "secret.txt row 2" in result.output


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/stdin", "/dev/null"])
def test_pulse_csv_must_be_a_regular_file(tmp_path: Path, device: str) -> None:
    if not Path(device).exists():
        pytest.skip(f"{device} missing")
    start = time.perf_counter()
    with pytest.raises(InputError, match="a regular file|at least 2"):
        read_pulse_csv(device)
    assert time.perf_counter() - start < 2.0


def test_pulse_csv_size_is_bounded(tmp_path: Path, monkeypatch) -> None:
    from vtool.assessments.sonic_boom import pulses

    big = tmp_path / "big.csv"
    big.write_text("t,p\n" + "0.0,1.0\n" * 1000)
    monkeypatch.setattr(pulses, "MAX_CSV_BYTES", 100)
    with pytest.raises(InputError, match="at most 100 bytes"):
        read_pulse_csv(big)


def test_a_bad_cell_is_cut_to_a_readable_length(tmp_path: Path) -> None:
    path = tmp_path / "p.csv"
    path.write_text("time,pressure\n0.0,1.0\n0.1," + "x" * 10_000 + "\n")
    with pytest.raises(InputError) as err:
        read_pulse_csv(path)
    assert "p.csv row 3 column 2" in str(err.value) and len(str(err.value)) < 200


def test_relative_pulse_csv_resolves_against_the_preset_folder(tmp_path: Path, monkeypatch) -> None:
    folder = tmp_path / "job"
    folder.mkdir()
    (folder / "boom.csv").write_text("time,pressure\n0,1\n0.1,0\n0.2,-1\n0.2001,0\n")
    preset = _csv_preset(folder, "boom.csv")
    monkeypatch.chdir(tmp_path)  # boom.csv is not in the working directory
    result = _run("boom", "wall", str(preset))
    assert result.exit_code == 0, result.output
    assert "csv:boom.csv" in result.output


def test_an_echoed_value_is_cut_to_a_readable_length() -> None:
    from vtool.presets import plate

    with pytest.raises(InputError) as err:
        boom.load(_edit(WALL, ("boom", "pulse"), "x" * 100_000))
    assert str(err.value).startswith("boom.pulse: got ") and len(str(err.value)) < 200
    doc = read_document(PRESET_DIR / "plate-table2.toml")
    doc["study"]["element"] = "y" * 100_000
    with pytest.raises(InputError) as err:
        plate.load(doc)
    assert len(str(err.value)) < 200


def test_huge_pulse_parameters_are_refused() -> None:
    from vtool.assessments.sonic_boom.pulses import PulseParams, validate

    with pytest.raises(InputError, match=r"s: got 1e\+308"):
        validate(PulseParams("N", s=1e308))
    assert samples_estimate(idealized("N", s=100.0), [1e4]) > MAX_SAMPLES
