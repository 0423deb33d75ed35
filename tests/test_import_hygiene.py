"""Layering: nothing below app/ imports textual, plotext, matplotlib or click (STYLE.md)."""

from __future__ import annotations

import subprocess
import sys

import pytest

HEADLESS = [
    "vtool.solvers",
    "vtool.assessments",
    "vtool.presets",
    "vtool.errors",
    "vtool.files",
    "vtool.units",
    "vtool.numba_cache",
    "vtool.chart",
]


@pytest.mark.parametrize("module", HEADLESS)
def test_headless_module_imports_no_ui(module: str) -> None:
    code = (
        "import importlib, pkgutil, sys\n"
        f"pkg = importlib.import_module({module!r})\n"
        "for info in pkgutil.walk_packages(getattr(pkg, '__path__', []), pkg.__name__ + '.'):\n"
        "    importlib.import_module(info.name)\n"
        "bad = [m for m in ('textual', 'plotext', 'click', 'matplotlib') if m in sys.modules]\n"
        "print(','.join(bad))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "", f"{module} pulls in {out.stdout.strip()}"


def test_no_bare_top_level_packages() -> None:
    """The installed code lives under `vtool` only, never as bare `app` or `solvers`."""
    import importlib.util

    import vtool.solvers

    for bare in ("app", "solvers", "assessments", "presets"):
        spec = importlib.util.find_spec(bare)
        if spec is not None and spec.origin:
            assert "site-packages" not in spec.origin, f"bare {bare} installed"
    assert vtool.solvers.__name__ == "vtool.solvers"


def test_cli_help_imports_no_numerics() -> None:
    code = (
        "import sys\nfrom click.testing import CliRunner\n"
        "from vtool.app.cli.main import cli\n"
        "r = CliRunner().invoke(cli, ['--help'])\n"
        "assert r.exit_code == 0, r.output\n"
        "print(','.join(m for m in ('numpy', 'numba', 'scipy', 'textual') if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def test_solve_imports_no_ui_and_no_study_tools() -> None:
    """`vtool solve PRESET` (newmark) never imports the TUI, plotting, cluster, TOML-writing or test tools.
    (numba's own start-up probe for BLAS imports ``scipy.linalg`` when it loads a compiled function;
    vtool leaves numba as it ships.)"""
    code = (
        "import sys\nfrom click.testing import CliRunner\n"
        "from vtool.app.cli.main import cli\n"
        "r = CliRunner().invoke(cli, ['solve', 'gnilka-1a'])\n"
        "assert r.exit_code == 0, r.output\n"
        "print(','.join(m for m in ('textual', 'plotext', 'matplotlib', 'dask', 'distributed', 'tomlkit', 'tomli_w',"
        " 'hypothesis', 'pytest', 'scipy.optimize', 'scipy.integrate') if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def test_import_linter_contracts_are_kept(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """pyproject's import-linter contracts (layers, no UI below app/, solvers without presets)."""
    from tests import typing_tree

    result = typing_tree.run_lint_imports(typing_tree.build(tmp_path))
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr[-2000:]
    assert "0 broken" in result.stdout


def test_the_kinds_table_names_importable_code() -> None:
    """Every dotted path in presets/kinds.py KINDS resolves (the CLI and the TUI read it)."""
    from vtool.presets.kinds import KINDS, resolve

    for kind in KINDS.values():
        assert isinstance(resolve(kind.spec_type), type)
        assert hasattr(resolve(kind.loader), "load") and callable(resolve(kind.solve))
        assert resolve(kind.screen).__name__ == kind.screen


def test_every_module_sits_in_an_import_contract() -> None:
    """Each top-level module of vtool/ and each layer package is named by an import-linter contract
    (the layers, or the core's forbidden contract): a new core module must be placed."""
    import tomllib

    from tests import typing_tree

    config = tomllib.loads((typing_tree.ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    named: set[str] = set()
    for contract in config["tool"]["importlinter"]["contracts"]:
        for layer in contract.get("layers", []):
            named |= {part.strip() for part in layer.replace("|", ":").split(":")}
        named |= set(contract.get("source_modules", []))
    modules = {f"vtool.{path.stem}" for path in (typing_tree.ROOT / "vtool").glob("*.py") if path.stem != "__init__"}
    modules |= {f"vtool.{folder}" for folder in typing_tree.FOLDERS}
    assert modules - named == set(), f"modules in no import contract: {sorted(modules - named)}"
