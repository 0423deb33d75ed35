"""``vtool report PRESET -o r.pdf|html``: every section, the figure count, the checks; the TUI writes the same."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest
from click.testing import CliRunner

from tests.tui_helpers import answer_path_dialog, run_and_wait
from vtool.app.cli.main import cli
from vtool.presets.report import FAIL, NOT_APPLICABLE, PASS, SECTIONS

SWEEP = ["--sweep", "run.rpm=9000,11000", "--sweep", "members.valve_spring.stiffness=200,300"]


def run(*args: str):
    return CliRunner().invoke(cli, list(args))


def html_sections(text: str) -> list[str]:
    return re.findall(r"<h2>(.*?)</h2>", text)


def test_html_report_has_every_section_and_its_figures_inline(tmp_path: Path) -> None:
    out = tmp_path / "r.html"
    result = run("report", "gnilka-1a", "-o", str(out))
    assert result.exit_code == 0, result.output
    assert f"wrote {out}: 5 sections, 3 figures" in result.output
    text = out.read_text()
    assert html_sections(text) == [s for s in SECTIONS if s != "Speed map"]
    figures = re.findall(r"<figure><svg.*?</svg><figcaption>", text, flags=re.S)
    assert len(figures) == 3
    # self-contained: no external reference, no script
    assert not re.search(r"(src|href)=\"(?!#)", text) and "<script" not in text
    # the model's members, the version, the checks with their outcomes, the accuracy note's step
    for member in ("pushrod", "left_rocker", "right_rocker", "valve_spring", "valve"):
        assert f"<td>{member}</td>" in text
    assert "<td>vtool</td><td>0.1.0</td>" in text
    assert re.search(r"<td>follower stays on the cam</td>.*?<td class=\"(pass|fail)\">", text)
    assert "<td>time step</td><td>1e-06 s</td>" in text


def test_html_report_with_a_sweep_has_the_speed_map(tmp_path: Path) -> None:
    out = tmp_path / "r.html"
    result = run("report", "gnilka-1a", "--degrees", "400", *SWEEP, "--metric", "peak_F1", "-o", str(out))
    assert result.exit_code == 0, result.output
    text = out.read_text()
    assert html_sections(text) == list(SECTIONS)
    assert len(re.findall(r"<figure><svg", text)) == 4
    speed_map = text[text.index("<h2>Speed map</h2>"):text.index("<h2>Accuracy note</h2>")]
    assert speed_map.count("<tr><td>") == 4  # the four points
    assert "run.rpm (rev/min)" in speed_map and "members.valve_spring.stiffness (lbf/in)" in speed_map


def pdf_page_count(data: bytes) -> int:
    return len(re.findall(rb"/Type /Page\b(?!s)", data))


def test_pdf_report_has_every_section_and_figure(tmp_path: Path) -> None:
    from vtool.app.report import pdf_pages
    from vtool.presets import load_preset
    from vtool.presets.report import valvetrain_report
    from vtool.presets.valvetrain import with_run_overrides

    out = tmp_path / "r.pdf"
    result = run("report", "gnilka-1a", "--degrees", "400", *SWEEP, "-o", str(out))
    assert result.exit_code == 0, result.output
    data = out.read_bytes()
    assert data.startswith(b"%PDF-") and data.rstrip().endswith(b"%%EOF")
    report = valvetrain_report(with_run_overrides(load_preset("gnilka-1a"), degrees=400.0), preset="gnilka-1a",
                               sweep=SWEEP[1::2])
    pages = [what for what, _ in pdf_pages(report)]
    assert sum(what.startswith("figure:") for what in pages) == len(report.figures) == 4
    text_titles = ", ".join(what for what in pages if what.startswith("text:"))
    assert all(title in text_titles for title in SECTIONS)
    assert pdf_page_count(data) == len(pages)
    if shutil.which("pdftotext"):  # poppler, where installed: the words on the pages
        words = subprocess.run(["pdftotext", str(out), "-"], capture_output=True, text=True, check=True).stdout
        for title in SECTIONS:
            assert title.upper() in words
        assert "follower stays on the cam" in words and "run.rpm (rev/min)" in words


def test_checks_judge_the_run_by_its_metrics() -> None:
    """1A at 11,000 rpm leaves the cam after the first revolution (the thesis' jump); 60 degrees cannot tell."""
    from vtool.presets import load_preset
    from vtool.presets.report import run_checks
    from vtool.presets.valvetrain import with_run_overrides
    from vtool.solvers.run import simulate
    from vtool.solvers.studies.metrics import run_metrics

    trace = simulate(load_preset("gnilka-1a"))
    checks = {c.name: c for c in run_checks(trace)}
    assert checks["run completes"].outcome == PASS
    separations = run_metrics(trace)["cam_separations"]
    assert separations >= 1
    assert checks["follower stays on the cam"].outcome == FAIL
    assert checks["follower stays on the cam"].value == f"{int(separations)} separation episodes"
    short = {c.name: c for c in run_checks(simulate(with_run_overrides(load_preset("gnilka-1a"), degrees=60.0)))}
    assert short["follower stays on the cam"].outcome == NOT_APPLICABLE


def test_report_refuses_a_bad_output_before_running(tmp_path: Path) -> None:
    result = run("report", "gnilka-1a", "-o", str(tmp_path / "r.docx"))
    assert result.exit_code == 2 and ".html or .pdf" in result.output
    result = run("report", "boom-brick-wall", "--sweep", "run.rpm=1,2", "-o", str(tmp_path / "r.pdf"))
    assert result.exit_code == 2 and "no sweep for a boom preset" in result.output
    result = run("report", "four-cylinder-intake", "-o", str(tmp_path / "r.pdf"))
    assert result.exit_code == 2 and "a preset of a kind with a report: valvetrain, boom_wall" in result.output
    result = run("report", "gnilka-1a", "--sweep", "run.rpm=9000", "-o", str(tmp_path / "r.pdf"))
    assert result.exit_code == 2 and "--sweep" in result.output
    assert not list(tmp_path.iterdir())


@pytest.mark.asyncio
async def test_tui_saves_the_same_report(tmp_path: Path) -> None:
    from vtool.app.tui.app import create_app

    app = create_app("gnilka-1c", remember=False, chart_color=False)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.pause()
        await run_and_wait(pilot, app)
        await answer_path_dialog(pilot, app, "ctrl+g", str(tmp_path / "tui.html"))
    assert run("report", "gnilka-1c", "-o", str(tmp_path / "cli.html")).exit_code == 0

    def content(name: str) -> str:  # the wall times differ between the two runs
        text = (tmp_path / name).read_text()
        return re.sub(r"[\d.]+ s of back-end wall time", "", text)

    tui, cli_text = content("tui.html"), content("cli.html")
    assert html_sections(tui) == html_sections(cli_text) and tui.count("<figure>") == cli_text.count("<figure>")
    assert tui == cli_text


def test_the_presets_checks_table_is_in_the_report() -> None:
    """A preset's [checks] limits (solvers/studies/checks.py) follow the run's own checks, with their margin."""
    import vtool
    from vtool.presets.report import run_checks

    document = vtool.load("gnilka-1a").document
    document["checks"] = {"seating_velocity_max": 1.0}  # in/s: 1A seats far faster, so it fails
    result = vtool.load(document).solve()
    checks = {c.name: c for c in run_checks(result.trace)}
    seating = checks["valve seating velocity (largest)"]
    largest = max(max(c.get("seating_velocities") or [0.0]) for c in result.summary()["clearances"])
    assert seating.outcome == FAIL and seating.criterion.startswith("<= 1 in/s")
    assert float(seating.margin.split()[0]) == pytest.approx(1.0 - largest, rel=1e-5)


BOOM_PLATE_SECTIONS = {"boom": ["Model", "Settings and version", "Results and checks", "Figures", "Accuracy note"],
                       "plate": ["Model", "Settings and version", "Study results and checks", "Figures",
                                 "Accuracy note"]}


def test_boom_report_has_its_sections_allowables_and_checks(tmp_path: Path) -> None:
    """`vtool report boom-brick-wall`: the allowable p+ of `vtool solve` (limits_dict) in a table, a check per
    row (frequency within the criterion's range), one design figure per curve set."""
    from vtool.assessments.sonic_boom.assess import assess
    from vtool.assessments.sonic_boom.report import limits_dict
    from vtool.presets import load_preset
    from vtool.presets.report import boom_report

    out = tmp_path / "b.html"
    result = run("report", "boom-brick-wall", "-o", str(out))
    assert result.exit_code == 0, result.output
    text = out.read_text()
    assert html_sections(text) == BOOM_PLATE_SECTIONS["boom"]
    limits = limits_dict(assess(load_preset("boom-brick-wall")))["limits"]
    report = boom_report(load_preset("boom-brick-wall"))
    table = report.section("Results and checks").tables[0]
    assert [row[5] for row in table.rows] == [f"{r['pressure_psi']:.4g}" for r in limits]
    checks = report.section("Results and checks").checks
    assert [c.outcome for c in checks] == [PASS if r["criterion_frequency_range_ok"] else FAIL for r in limits]
    assert text.count("<figure>") == len(report.figures) >= 1 and "allowable p+" in text
    assert result.output.strip() == f"wrote {out}: 5 sections, {len(report.figures)} figures"


@pytest.mark.slow
def test_plate_report_has_its_sections_study_and_convergence_checks(tmp_path: Path) -> None:
    """`vtool report plate-table2 -o r.pdf`: the study's tables, a check per exact reference (acceleration
    converged: uniform load 7.6 %, so it fails), the transient figures on pages of their own."""
    from vtool.app.report import pdf_pages
    from vtool.presets import load_preset
    from vtool.presets.report import plate_report

    out = tmp_path / "p.pdf"
    result = run("report", "plate-table2", "-o", str(out))
    assert result.exit_code == 0, result.output
    assert out.read_bytes().startswith(b"%PDF")
    report = plate_report(load_preset("plate-table2"))
    assert [s.title for s in report.sections] == BOOM_PLATE_SECTIONS["plate"]
    checks = {c.name: c for c in report.section("Study results and checks").checks}
    assert checks["uniform exact reference"].outcome == FAIL and float(
        checks["uniform exact reference"].value.split()[0]) > 1.0
    assert "Table 2" in report.section("Study results and checks").text[0]
    pages = [what for what, _ in pdf_pages(report)]
    assert sum(what.startswith("figure:") for what in pages) == len(report.figures) >= 1


@pytest.mark.slow
@pytest.mark.asyncio
@pytest.mark.parametrize("preset, kind", [("boom-brick-wall", "boom"), ("plate-table3", "plate")])
async def test_tui_boom_and_plate_screens_save_the_report(tmp_path: Path, preset: str, kind: str) -> None:
    """ctrl+g on the boom and plate screens writes what `vtool report` writes (the plate's cost table holds
    wall times: compared without them)."""
    from vtool.app.tui.app import create_app

    app = create_app(preset, remember=False, chart_color=False)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.pause()
        await run_and_wait(pilot, app)
        await answer_path_dialog(pilot, app, "ctrl+g", str(tmp_path / "tui.html"))
    assert run("report", preset, "-o", str(tmp_path / "cli.html")).exit_code == 0

    def content(name: str) -> str:
        text = (tmp_path / name).read_text()
        return re.sub(r"\d+\.\d+e-\d+|\d+\.\d+", "#", text) if kind == "plate" else text

    tui, cli_text = content("tui.html"), content("cli.html")
    assert html_sections(tui) == BOOM_PLATE_SECTIONS[kind]
    assert tui.count("<figure>") == cli_text.count("<figure>") >= 1
    if kind == "boom":
        assert tui == cli_text
