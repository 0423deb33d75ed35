"""The valve-train tables in README.md and docs/valvetrain.md reproduce from benchmarks/tables_valvetrain.py.

Every column but the wall times is regenerated and compared with the
committed block. The exact and Newmark rows of all six presets are checked;
scipy rows (a few seconds per preset) for example 1A only, and for every
preset with VTOOL_FULL_TABLES=1; they are compared only under the scipy and
numpy versions the committed rows name. After a change to the solver,
``python3 benchmarks/tables_valvetrain.py`` rewrites the tables.
"""

from __future__ import annotations

import importlib.util
import os
import sys
from pathlib import Path

import pytest

from vtool.markdown import read_block
from vtool.solvers.studies.accuracy import library_versions

ROOT = Path(__file__).resolve().parents[1]
HINT = "the committed table differs: regenerate with `python3 benchmarks/tables_valvetrain.py`"


def _script():  # noqa: ANN202
    spec = importlib.util.spec_from_file_location("tables_valvetrain", ROOT / "benchmarks" / "tables_valvetrain.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


tables = _script()
# one worker takes the whole module: its studies (about 12 s) are computed once, not on every worker
pytestmark = pytest.mark.xdist_group("tables_valvetrain")
SCIPY_PRESETS = tables.PRESETS if os.environ.get("VTOOL_FULL_TABLES") else ("gnilka-1a",)


def test_the_module_runs_on_one_worker(request: pytest.FixtureRequest) -> None:
    """Under ``--dist loadgroup`` (pyproject's addopts) pytest-xdist names the group in the test's id; a pytest
    that drops the name (9.2 with xdist 3.8) spreads the module over the workers, each computing the studies."""
    if os.environ.get("PYTEST_XDIST_WORKER") and request.config.getoption("loadgroup", False):  # (set on workers)
        assert request.node.nodeid.endswith("@tables_valvetrain"), request.node.nodeid


@pytest.fixture(scope="module")
def studies() -> dict:
    return {name: tables.study(name, scipy=name in SCIPY_PRESETS) for name in tables.PRESETS}


def committed(path: Path, name: str) -> list[list[str]]:
    return tables.deterministic(read_block(path, name))


def without_scipy(rows: list[list[str]]) -> list[list[str]]:
    return [row for row in rows if row[0] != "scipy"]


@pytest.mark.parametrize("name", tables.PRESETS)
def test_exact_and_newmark_rows_of_every_preset_reproduce(studies: dict, name: str) -> None:
    ours = tables.deterministic(tables.accuracy_block(studies[name]))
    assert without_scipy(ours) == without_scipy(committed(tables.DOC, f"accuracy-{name.removeprefix('gnilka-')}")), HINT


@pytest.mark.parametrize("name", SCIPY_PRESETS)
def test_scipy_rows_reproduce_under_the_recorded_versions(studies: dict, name: str) -> None:
    theirs = [row for row in committed(tables.DOC, f"accuracy-{name.removeprefix('gnilka-')}") if row[0] == "scipy"]
    assert theirs, "no scipy rows committed"
    if any(not row[-1].endswith(library_versions()) for row in theirs):  # (a note may come before them)
        pytest.skip(f"committed scipy rows are for {theirs[0][-1]}; installed: {library_versions()}")
    ours = [row for row in tables.deterministic(tables.accuracy_block(studies[name])) if row[0] == "scipy"]
    assert ours == theirs, HINT


def test_readme_worst_case_and_default_tables_reproduce(studies: dict) -> None:
    results = [studies[name] for name in tables.PRESETS]
    worst = tables.deterministic(tables.worst_block(results))
    assert without_scipy(worst) == without_scipy(committed(tables.README, "accuracy-worst")), HINT
    default = tables.deterministic(tables.default_block(results))
    assert default == committed(tables.README, "accuracy-default"), HINT


def test_speed_tables_reproduce_steps_and_events(studies: dict) -> None:
    ours = tables.deterministic(tables.speed_block([studies[name] for name in tables.PRESETS], None))
    # the rows are sorted by wall time: compare them as a set
    assert sorted(ours[1:]) == sorted(committed(tables.README, "speed")[1:]), HINT
    assert committed(tables.DOC, "speed") == committed(tables.README, "speed")


def test_table_6_1_reproduces(studies: dict) -> None:
    from vtool.solvers.run import simulate

    ours = tables.deterministic(tables.table_6_1_block(simulate(studies["gnilka-1a"].spec)))
    assert ours == committed(tables.DOC, "table-6-1"), HINT
