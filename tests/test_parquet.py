"""``--format parquet`` (solvers/parquet.py): the same numbers as the CSV, in row groups; one line without pyarrow."""

from __future__ import annotations

import csv
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from vtool.app.cli.main import cli

pq = pytest.importorskip("pyarrow.parquet")


def run(*args: str):
    return CliRunner().invoke(cli, list(args))


def read_csv(path: Path) -> tuple[list[str], list[list[str]]]:
    rows = list(csv.reader(path.open()))
    return rows[0], rows[1:]


def test_every_step_parquet_has_the_csv_numbers_in_row_groups(tmp_path: Path) -> None:
    from vtool.solvers.parquet import ROW_GROUP

    result = run("solve", "gnilka-1a", "--every-step", "--out", str(tmp_path / "run.parquet"))
    assert result.exit_code == 0, result.output
    assert run("solve", "gnilka-1a", "--every-step", "--csv", str(tmp_path / "run.csv")).exit_code == 0
    header, rows = read_csv(tmp_path / "run.csv")
    parquet = pq.ParquetFile(tmp_path / "run.parquet")
    table = parquet.read()
    assert table.num_rows == len(rows) > ROW_GROUP  # a run of more steps than one group
    assert parquet.metadata.num_row_groups == math.ceil(len(rows) / ROW_GROUP)
    assert f"wrote {len(rows)} rows to" in result.output
    # every numeric column (named as the CSV names it, once) equal to the CSV's 10 significant digits
    names = list(dict.fromkeys(header[:-2]))
    assert table.schema.names == ["time (s)", "cam_angle (deg)", *names[2:], "configuration", "closed"]
    for name in names:
        column = header.index(name)
        expected = np.array([float(r[column]) if r[column] else math.nan for r in rows])
        assert np.allclose(table.column(name).to_numpy(), expected, rtol=6e-10, atol=0.0, equal_nan=True), name
    configuration = [int(r[-2]) if r[-2] else None for r in rows]
    assert table.column("configuration").to_pylist() == configuration
    assert table.column("closed").to_pylist() == [r[-1] for r in rows]
    assert parquet.schema_arrow.metadata[b"title"].decode().startswith("Gnilka 1971 example 1A")


def test_sweep_parquet_has_the_csv_points(tmp_path: Path) -> None:
    sweep = ["sweep", "gnilka-1d", "--set", "run.rpm=9000,10000,11000", "--set", "run.degrees=400", "--workers", "1"]
    result = run(*sweep, "--format", "parquet", "--out", str(tmp_path / "points.pq"))
    assert result.exit_code == 0, result.output
    assert "wrote 3 rows to" in result.output and "peak_F1" not in result.output  # the file has the table
    assert run(*sweep, "--csv", str(tmp_path / "points.csv")).exit_code == 0
    header, rows = read_csv(tmp_path / "points.csv")
    table = pq.read_table(tmp_path / "points.pq")
    assert table.schema.names == ["point", *header]
    by_point = sorted(zip(table.column("point").to_pylist(), range(table.num_rows), strict=True))
    for (point, row), expected in zip(by_point, rows, strict=True):
        assert point == rows.index(expected)
        for name, cell in zip(header, expected, strict=True):
            value = table.column(name)[row].as_py()
            if name == "status":
                assert value == cell
            else:
                assert (math.isnan(value) and cell == "") or value == pytest.approx(float(cell), rel=1e-9)


def test_sweep_writer_holds_at_most_one_row_group(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Memory bounded: the sink never buffers more than ROW_GROUP points (here 100, for a small test)."""
    import vtool.solvers.parquet as parquet
    from vtool.files import open_atomic_binary
    from vtool.presets import load_preset
    from vtool.solvers.studies.metrics import metric_columns
    from vtool.solvers.studies.sweep import PointResult

    monkeypatch.setattr(parquet, "ROW_GROUP", 100)
    spec = load_preset("gnilka-1d")
    names = [name for name, _ in metric_columns(spec)]
    most = 0
    with open_atomic_binary(tmp_path / "s.parquet") as handle:
        sink = parquet.SweepParquet(handle, (("run.rpm", "rev/min"),), spec)
        for i in range(1050):
            sink.append(PointResult(i, (("run.rpm", 1000.0 + i),), dict.fromkeys(names, float(i))))
            most = max(most, sink.groups.buffered)
        sink.finish()
    assert most < 100
    file = pq.ParquetFile(tmp_path / "s.parquet")
    assert file.metadata.num_row_groups == 11 and file.metadata.num_rows == 1050
    assert file.read().column("run.rpm (rev/min)").to_pylist() == [1000.0 + i for i in range(1050)]


def test_parquet_refusals_are_one_line(tmp_path: Path) -> None:
    result = run("sweep", "gnilka-1d", "--set", "run.rpm=9000,10000", "--format", "parquet", "--resume",
                 "--out", str(tmp_path / "p.parquet"))
    assert result.exit_code == 2 and "csv for --resume" in result.output
    result = run("solve", "gnilka-1d", "--format", "parquet")
    assert result.exit_code == 2 and "an output file" in result.output
    result = run("solve", "boom-brick-wall", "--format", "parquet", "--out", str(tmp_path / "b.parquet"))
    assert result.exit_code == 2 and "--format applies to valvetrain presets" in result.output
    assert not list(tmp_path.iterdir())


def test_without_pyarrow_parquet_is_one_line_and_nothing_runs(tmp_path: Path) -> None:
    """pyarrow is an optional extra: without it, asking for Parquet is one line, exit 2, before the run."""
    code = ("import sys\n"
            "sys.modules['pyarrow'] = None; sys.modules['pyarrow.parquet'] = None  # import now fails\n"
            "from vtool.app.cli.main import main\n"
            f"sys.argv = ['vtool', 'solve', 'gnilka-1a', '--every-step', '--out', {str(tmp_path / 'r.parquet')!r}]\n"
            "main()\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        "error: --format: got 'parquet', expected pyarrow installed for Parquet output "
        "(pip install 'vtool[parquet]'); or --format csv"]
    assert done.stdout == "" and not list(tmp_path.iterdir())
