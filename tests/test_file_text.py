"""What vtool reads and writes as text (issue 37): CSV headers and quoting, text fields, file content in
errors, TOML that takes too long to parse, ``vtool solve --set``."""

from __future__ import annotations

import csv
import io
import time
import tomllib
from pathlib import Path

import pytest

from tests.test_outputs import one_line, run
from vtool.errors import InputError
from vtool.presets import PRESET_DIR, load_document, parse_text


def rows_of(path: Path) -> list[list[str]]:
    return list(csv.reader(io.StringIO(path.read_text(encoding="utf-8"))))


# ----- the valve-train CSV -----------------------------------------------------------------------

def test_solve_csv_headers_are_unique_and_hold_the_valve_lift(tmp_path: Path) -> None:
    out = tmp_path / "r.csv"
    result = run("solve", "gnilka-1a", "--degrees", "360", "--csv", str(out))
    assert result.exit_code == 0, result.output
    rows = rows_of(out)
    header = rows[0]
    assert len(header) == len(set(header)), [h for h in header if header.count(h) > 1]
    assert {len(r) for r in rows} == {len(header)}
    # the seat clearance (valve q7 on seat q10) is its gap: valve_lift = q7 - q10, 0 when seated
    lift = [float(r[header.index("valve_lift (in)")]) for r in rows[1:]]
    q7 = [float(r[header.index("q7 (in)")]) for r in rows[1:]]
    q10 = [float(r[header.index("q10 (in)")]) for r in rows[1:]]
    assert max(abs(a - (b - c)) for a, b, c in zip(lift, q7, q10, strict=True)) < 1e-8
    assert min(lift) > -1e-6 and max(lift) > 0.1
    # the preset's quantities that were already columns are written once; the others are there
    assert header.count("q9 (in)") == 1 and header.count("F1 (lbf)") == 1 and "q1-q9 (in)" in header


def test_solve_takes_set_like_sweep(tmp_path: Path) -> None:
    import json

    stiff = run("solve", "gnilka-1a", "--degrees", "60", "--json", "--set", "members.valve_spring.stiffness=400")
    plain = run("solve", "gnilka-1a", "--degrees", "60", "--json")
    assert stiff.exit_code == 0 and plain.exit_code == 0, stiff.output
    assert json.loads(stiff.stdout)["clearances"] != json.loads(plain.stdout)["clearances"]
    for args, text in [(["--set", "run.rpm=1,2"], "expected one value"),
                       (["--set", "run.nope=3"], "run.nope: got 3"),
                       (["--set", "run.rpm=-5"], "run.rpm: got -5, expected >= 0.001"),
                       (["--set", "run.rpm"], "expected FIELD=VALUES")]:
        result = run("solve", "gnilka-1a", *args)
        assert result.exit_code == 2 and text in one_line(result), (args, result.stderr)


# ----- text fields and CSV quoting ---------------------------------------------------------------

def plate_doc(name: str) -> dict:  # type: ignore[type-arg]
    doc = tomllib.loads((PRESET_DIR / "plate-irs.toml").read_text(encoding="utf-8"))
    h5 = next(c for c in doc["cases"] if c["name"] == "H5")  # a case the transient list does not name
    h5["name"] = name
    return doc


@pytest.mark.parametrize("name", ["H5\n", "H\r5", "H5\x1b[31m", "H\u202e5", "H5\u2028", "\x00"])
def test_a_text_field_with_a_control_character_is_refused_in_one_line(name: str) -> None:
    with pytest.raises(InputError) as caught:
        load_document(plate_doc(name))
    line = caught.value.one_line()
    assert line.startswith("cases[") and "control character" in line and "\n" not in line


def test_notes_may_hold_line_breaks() -> None:
    doc = plate_doc("H5b")
    doc["notes"] = "two\nlines\twith a tab"
    assert load_document(doc).notes == "two\nlines\twith a tab"


def test_a_case_name_with_a_comma_and_quotes_is_quoted_in_every_plate_csv(tmp_path: Path) -> None:
    import tomli_w

    preset = tmp_path / "p.toml"
    preset.write_text(tomli_w.dumps(plate_doc('H5, "fine"')))
    for command, extra in (("modes", []), ("study", ["--no-transient"])):
        out = tmp_path / f"{command}.csv"
        result = run("plate", command, str(preset), *extra, "--csv", str(out))
        assert result.exit_code == 0, result.output
        rows = rows_of(out)
        assert len({len(r) for r in rows}) == 1, command
        assert any('H5, "fine"' in r for r in rows), command


# ----- file content never in a message -----------------------------------------------------------

SECRET = "BEGIN-PRIVATE-KEY-MATERIAL-0123456789"


def ramped_with_table(folder: Path, table: Path) -> Path:
    text = (PRESET_DIR / "ramped-cam.toml").read_text(encoding="utf-8")
    lines = [line for line in text.splitlines() if not line.startswith("lift_table")]
    at = lines.index("[cam]") + 1
    lines.insert(at, f'lift_table = "{table}"')
    preset = folder / "p.toml"
    preset.write_text("\n".join(lines) + "\n")
    return preset


@pytest.mark.parametrize("content, words", [
    (f"angle,lift\n{SECRET}\n", "line 2"),
    (f"0,0\n10 0.1 {SECRET}\n", "line 2"),
    (f"# {SECRET}\n0,0\n1,x{SECRET}\n", "line 3"),
])
def test_a_lift_table_error_names_the_line_but_never_shows_it(tmp_path: Path, content: str, words: str) -> None:
    table = tmp_path / "secret.txt"
    table.write_text(content)
    result = run("solve", str(ramped_with_table(tmp_path, table)))
    line = one_line(result)
    assert result.exit_code == 2 and words in line and f"({table.name})" in line
    assert SECRET not in result.output and "MATERIAL" not in result.stderr


def test_a_pulse_csv_error_never_shows_a_cell(tmp_path: Path) -> None:
    pulse = tmp_path / "pulse.csv"
    pulse.write_text(f"t,p\n0,0\n0.1,{SECRET}\n")
    result = run("boom", "daf", "--pulse-csv", str(pulse))
    assert result.exit_code == 2 and "row 3 column 2" in one_line(result) and SECRET not in result.stderr


# ----- TOML that takes too long to parse ---------------------------------------------------------

@pytest.mark.parametrize("text", [
    "a" + ".a" * 20_000 + " = 1\n",  # 33 s in tomllib
    "[" + "a." * 200_000 + "a]\n",  # a 400 kB header: minutes
    "[" + '"a".' * 100_000 + '"a"]\n',
    "x = {" + "a." * 200_000 + "a = 1}\n",
], ids=["dotted-key-20000", "header-400kB", "quoted-header", "inline-table"])
def test_a_dotted_key_of_thousands_of_parts_is_refused_at_once(text: str) -> None:
    started = time.perf_counter()
    with pytest.raises(InputError, match="at most 100 parts"):
        parse_text(text)
    assert time.perf_counter() - started < 1.0


def test_dots_in_values_and_strings_are_not_keys() -> None:
    doc = parse_text("x = [" + ", ".join(["1.5"] * 2000) + "]\n" + 'y = "' + "." * 5000 + '"\n' + "a.b.c = 1\n")
    assert len(doc["x"]) == 2000 and doc["a"]["b"]["c"] == 1
