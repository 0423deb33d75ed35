"""Static typing: mypy resolves every `vtool.*` import and runs clean on solvers/ and presets/.

mypy runs on the installed layout built by :mod:`tests.typing_tree` (the
editable install's import hook is invisible to it), with pyproject's
``[tool.mypy]`` configuration; ``py.typed`` ships in the wheel.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy
import pytest
from numpy.lib import NumpyVersion

from tests import typing_tree

# one worker, early (see conftest.py): mypy on an empty cache takes 15 s; last in the run, it was the tail
pytestmark = pytest.mark.xdist_group("typing")


@pytest.fixture(scope="module")
def tree(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return typing_tree.build(tmp_path_factory.mktemp("typing"))


#: The gate is kept against NumPy 2.4.6's type stubs and skipped under NumPy 2.0, whose stubs lack
#: ``np.trapezoid`` and type a few functions otherwise (NumPy 2.0.2, 2026-11-28: 17 errors in 6 files, all
#: from the stubs; the whole suite passes there). NumPy 2.1 to 2.3 were not tried: the gate runs under them.
STUBS_FROM = "2.1.0"


@pytest.mark.skipif(shutil.which("mypy") is None and not Path(typing_tree.sys.executable).with_name("mypy").exists(),
                    reason="mypy is in the dev extra")
@pytest.mark.skipif(NumpyVersion(numpy.__version__) < STUBS_FROM,
                    reason=f"NumPy {numpy.__version__}'s type stubs are older than the gate's (NumPy 2.1 on)")
def test_mypy_is_clean_on_solvers_and_presets(tree: Path) -> None:
    result = typing_tree.run_mypy(tree)
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr[-2000:]
    assert "Success: no issues found" in result.stdout
    assert "Cannot find implementation or library stub" not in result.stdout


def test_py_typed_is_shipped() -> None:
    assert (typing_tree.ROOT / "vtool" / "py.typed").exists()
    text = (typing_tree.ROOT / "pyproject.toml").read_text(encoding="utf-8")
    assert '"vtool" = ["py.typed"]' in text


def test_no_error_code_is_switched_off_for_a_module() -> None:
    """The gate is the whole package: no [[tool.mypy.overrides]] block disables error codes."""
    import tomllib

    config = tomllib.loads((typing_tree.ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    blocks = config["tool"]["mypy"].get("overrides", [])
    assert [block["module"] for block in blocks if "disable_error_code" in block] == []
    assert "-p vtool" in " ".join(typing_tree.MYPY_TARGETS) and len(typing_tree.MYPY_TARGETS) == 2


def test_every_type_ignore_names_its_code_and_a_reason() -> None:
    """``# type: ignore[code]  # why`` (or ``... [code] (why)``): never a bare ignore, never one without a word
    on why."""
    import re

    bare = re.compile(r"#\s*type:\s*ignore(?!\[)")
    no_reason = re.compile(r"#\s*type:\s*ignore\[[^\]]*\]\s*$")
    found = []
    for folder in ("vtool", *typing_tree.FOLDERS):
        for path in sorted((typing_tree.ROOT / folder).rglob("*.py")):
            for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
                if bare.search(line) or no_reason.search(line):
                    found.append(f"{path.relative_to(typing_tree.ROOT)}:{number}: {line.strip()}")
    assert found == [], "type: ignore without a code and a reason:\n" + "\n".join(found)
