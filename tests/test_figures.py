"""``--figure out.png|svg|pdf`` on every command that plots: the file type, and axes labelled with units."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from tests.test_plate_cli import SMALL
from vtool.app.cli.main import cli
from vtool.chart import Chart, HeatMap

MAGIC = {"png": b"\x89PNG\r\n\x1a\n", "pdf": b"%PDF-"}
UNIT = re.compile(r"\(([^()]+)\)\s*$")  # a label ends with its unit in parentheses


def run(*args: str):
    return CliRunner().invoke(cli, list(args))


def check_file(path: Path, fmt: str) -> str:
    data = path.read_bytes()
    if fmt == "svg":
        text = data.decode("utf-8")
        assert text.lstrip().startswith("<?xml") and "<svg" in text and text.rstrip().endswith("</svg>")
        return text
    assert data.startswith(MAGIC[fmt]), data[:16]
    if fmt == "pdf":
        assert data.rstrip().endswith(b"%%EOF")
    return ""


def commands(tmp_path: Path) -> dict[str, list[str]]:
    small = tmp_path / "small.toml"
    small.write_text(SMALL)
    return {
        "solve": ["solve", "gnilka-1a", "--degrees", "40"],
        "sweep": ["sweep", "gnilka-1d", "--set", "run.rpm=9000,11000", "--set", "run.degrees=20",
                  "--set", "members.valve_spring.stiffness=200,300", "--metric", "peak_F1", "--map",
                  "--workers", "1"],
        "cam": ["cam", "show", "ramped-cam"],
        "compare": ["compare", "gnilka-1d", "--degrees", "20", "--impact", "local,thesis"],
        "boom daf": ["boom", "daf", "--range", "0:2:0.05"],
        "boom wall": ["boom", "wall", "boom-brick-wall"],
        "plate study": ["plate", "study", str(small)],
        "solve --orders": ["solve", "gnilka-1a", "--orders", "F7"],
        "sweep --campbell": ["sweep", "gnilka-1a", "--set", "run.rpm=9000:10000:500", "--campbell", "F7",
                             "--workers", "1"],
    }


# each command in every format would be 21 runs; solve takes all three, the others one each, in turn
CASES = [("solve", fmt) for fmt in ("png", "svg", "pdf")] + [
    (name, ("svg", "png", "pdf")[i % 3])
    for i, name in enumerate(["sweep", "cam", "compare", "boom daf", "boom wall", "plate study", "solve --orders",
                              "sweep --campbell"])]


@pytest.mark.parametrize(("name", "fmt"), CASES)
def test_each_plotting_command_writes_a_figure(tmp_path: Path, name: str, fmt: str) -> None:
    out = tmp_path / f"figure.{fmt}"
    result = run(*commands(tmp_path)[name], "--figure", str(out))
    assert result.exit_code == 0, result.output
    assert f"wrote {out}" in result.output
    text = check_file(out, fmt)
    if fmt == "svg":  # text stays text: the axis labels, with their units, are in the file
        labels = re.findall(r"<text[^>]*>([^<]*)</text>", text)
        assert any(UNIT.search(label) for label in labels), labels[:20]


def test_figure_refuses_an_unknown_suffix_before_running(tmp_path: Path) -> None:
    result = run("solve", "gnilka-1a", "--figure", str(tmp_path / "out.jpg"))
    assert result.exit_code == 2
    assert "--figure" in result.output and ".png, .svg or .pdf" in result.output
    assert "steps" not in result.output  # nothing ran
    result = run("solve", "gnilka-1a", "--figure", str(tmp_path / "missing" / "out.png"))
    assert result.exit_code == 2 and "does not exist" in result.output


def _axes_labels(figure) -> list[tuple[str, str]]:  # type: ignore[no-untyped-def]
    return [(ax.get_xlabel(), ax.get_ylabel()) for ax in figure.get_axes() if ax.get_xlabel() or ax.get_ylabel()]


def test_every_chart_of_a_run_labels_its_axes_with_units() -> None:
    """The figure's axes carry the chart data's labels; each names its unit; the preset's title heads it."""
    from vtool.app.figures import build_figure
    from vtool.presets import load_preset
    from vtool.presets.charts import cam_charts, trace_charts
    from vtool.presets.valvetrain import with_run_overrides
    from vtool.solvers.run import simulate

    spec = load_preset("gnilka-1a")
    trace = simulate(with_run_overrides(spec, degrees=60.0))
    charts = trace_charts(trace) + cam_charts(spec)
    for chart in charts:
        for label in chart.labels():
            assert UNIT.search(label), (chart.title, label)
    figure = build_figure(charts)
    bottom_labels = [x for x, _ in _axes_labels(figure) if x]
    assert bottom_labels.count("cam angle (deg)") == len(charts)  # the x label under each chart
    ylabels = [y for _, y in _axes_labels(figure) if y]
    assert "contact force (lbf)" in ylabels and "displacement (in)" in ylabels
    assert figure.get_suptitle() == spec.title
    # the events of the run are marked on the force panel, by kind, with their count
    force_axes = next(ax for ax in figure.get_axes() if ax.get_ylabel() == "contact force (lbf)")
    legend = [t.get_text() for t in force_axes.get_legend().get_texts()]
    impacts = sum(1 for e in trace.events if e.kind == "closed")
    assert f"impact ({impacts})" in legend


def test_curves_differ_without_colour() -> None:
    """Black-and-white readable: no two curves of a panel share both line style and marker."""
    import numpy as np

    from vtool.app.figures import build_figure
    from vtool.chart import Panel, curve

    x = np.linspace(0.0, 1.0, 50)
    panel = Panel(tuple(curve(f"c{k}", x, x * k) for k in range(12)), "y (m)")
    figure = build_figure([Chart("twelve", "x (s)", (panel,))])
    lines = figure.get_axes()[0].get_lines()
    looks = {(line.get_linestyle(), line.get_marker()) for line in lines}
    assert len(looks) == len(lines) == 12


def test_a_heat_map_names_its_three_axes() -> None:
    import numpy as np

    from vtool.app.figures import build_figure

    heat = HeatMap("peak (N)", "speed (rev/min)", "stiffness (N/mm)", "peak (N)", np.array([1.0, 2.0, 3.0]),
                   np.array([10.0, 20.0]), np.array([[1.0, np.nan, 3.0], [4.0, 5.0, 6.0]]))
    figure = build_figure([heat])
    ax, bar = figure.get_axes()
    assert (ax.get_xlabel(), ax.get_ylabel(), bar.get_ylabel()) == ("speed (rev/min)", "stiffness (N/mm)",
                                                                     "peak (N)")
    assert "blank: no value" in ax.get_title()


def test_docs_figures_are_embedded_and_regenerate() -> None:
    """benchmarks/docs_figures.py --check: every PNG docs/figures.md embeds exists; one redrawn is a small PNG."""
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    sys.path.insert(0, str(root / "benchmarks"))
    try:
        import docs_figures
    finally:
        sys.path.pop(0)
    assert set(docs_figures.FIGURES) == {p.stem for p in (root / "docs" / "figures").glob("*.png")}
    assert docs_figures.main(["--check", "--only", "boom-daf"]) == 0


def test_order_spectrum_and_campbell_figures_name_their_axes() -> None:
    """The --orders spectrum (natural frequencies marked at their orders) and the --campbell map."""
    from vtool.app.figures import build_figure
    from vtool.presets import load_preset
    from vtool.presets.charts import campbell_chart, order_chart
    from vtool.solvers.run import simulate
    from vtool.solvers.studies.orders import Campbell, natural_frequencies, spectrum

    trace = simulate(load_preset("gnilka-1a"))
    frequencies = natural_frequencies(trace)
    chart = order_chart(spectrum(trace, "F7"), frequencies)
    assert chart.labels() == ["cam order (-)", "amplitude (lbf)"]
    cam_hz = trace.spec.run.rpm / 60.0
    shown = [hz / cam_hz for _, hz in frequencies if hz / cam_hz <= chart.panels[0].curves[0].x[-1]]
    assert np.allclose(np.sort(chart.marks[0].x), np.sort(shown))
    data = Campbell("F7", "lbf", np.array([9000.0, 9500.0]), np.array([[1.0, 10.0], [0.0, 100.0]]), [])
    heat = campbell_chart(data)
    assert heat.labels() == ["cam speed (rev/min)", "cam order (-)", "log10 amplitude (lbf)"]
    assert np.allclose(heat.values, [[0.0, 1.0], [np.nan, 2.0]], equal_nan=True)
    figure = build_figure([chart, heat])
    assert {ax.get_xlabel() for ax in figure.get_axes()} >= {"cam order (-)", "cam speed (rev/min)"}


def test_the_campbell_figure_draws_the_natural_frequencies_the_terminal_map_marks() -> None:
    """Each natural frequency is the line order = f_n 60 / rpm over the map, labelled with its Hz; the cells
    the terminal map marks 'o' are those the line passes through (rounded order)."""
    from vtool.app.figures import build_figure
    from vtool.app.sweep_charts import campbell_map
    from vtool.presets.charts import campbell_chart
    from vtool.solvers.studies.orders import Campbell

    rpm = np.array([6000.0, 9000.0, 12000.0])
    data = Campbell("F7", "lbf", rpm, np.ones((24, 3)), [("all closed", 1200.0), ("start", 2000.0)])
    heat = campbell_chart(data)
    assert [line.label for line in heat.lines] == ["1200 Hz (all closed)", "2000 Hz (start)"]
    assert np.allclose(heat.lines[0].y, [12.0, 8.0, 6.0]) and np.allclose(heat.lines[1].y, [20.0, 40 / 3, 10.0])
    text = campbell_map(data).splitlines()
    rows = {int(line.split("|")[0]): line.split("|")[1][::2] for line in text
            if line.count("|") == 2 and line.split("|")[0].strip().isdigit()}
    for line in heat.lines:
        for j, order in enumerate(line.y):
            assert rows[round(order)][j] == "o"
    figure = build_figure([heat])
    ax = next(a for a in figure.get_axes() if a.get_xlabel() == "cam speed (rev/min)")
    drawn = {line.get_label(): line.get_ydata() for line in ax.get_lines()}
    assert set(drawn) == {"1200 Hz (all closed)", "2000 Hz (start)"}
    assert np.allclose(drawn["1200 Hz (all closed)"], [12.0, 8.0, 6.0])
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["1200 Hz (all closed)", "2000 Hz (start)"]
