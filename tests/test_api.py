"""The Python API (vtool/api.py): docs/api.md's examples and every examples/ script run; numbers checked."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = sorted((ROOT / "examples").glob("*.py"))


def code_blocks(path: Path) -> list[str]:
    return re.findall(r"```python\n(.*?)```", path.read_text(), flags=re.S)


def test_docs_api_examples_run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.chdir(tmp_path)
    blocks = code_blocks(ROOT / "docs" / "api.md")
    assert len(blocks) >= 7
    namespace: dict = {"__name__": "docs_api"}
    for block in blocks:
        exec(compile(block, "docs/api.md", "exec"), namespace)  # noqa: S102 - the page's own examples
    out = capsys.readouterr().out
    assert "254.0" in out and "run.rpm: got -5" in out
    assert "['time (s)', 'cam_angle (deg)', 'q1 (in)', 'q2 (in)']" in out
    assert "4 points" in out and "['run.html', 'run.png']" in out


@pytest.mark.slow
@pytest.mark.parametrize("script", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_example_script_runs(script: Path, tmp_path: Path) -> None:
    env = dict(os.environ, PYTHONWARNINGS="ignore")
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, cwd=tmp_path, env=env,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "Gnilka 1971" in done.stdout


def test_examples_cover_the_three_tasks() -> None:
    assert {p.stem for p in EXAMPLES} >= {"jump_speed", "spring_preload", "compare_laws"}


def test_import_vtool_is_light_and_the_api_loads_on_first_use() -> None:
    code = ("import sys, vtool, vtool.errors\n"
            "light = not any(m in sys.modules for m in ('numpy', 'vtool.api', 'vtool.presets'))\n"
            "load = vtool.load\n"
            "print(light, 'vtool.api' in sys.modules, load is sys.modules['vtool.api'].load)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["True", "True", "True"]


def test_unknown_attribute_is_an_attribute_error() -> None:
    import vtool

    with pytest.raises(AttributeError, match="no attribute 'nonsense'"):
        vtool.nonsense  # noqa: B018
    assert "load" in dir(vtool)


def test_arrays_are_the_csv_columns_and_the_trace() -> None:
    import vtool

    result = vtool.load("gnilka-1a").set(degrees=30.0).solve()
    columns = result.arrays()
    text = result.trace.csv_text(result.spec.run.quantities)  # what `vtool solve --csv` writes
    header = text.splitlines()[0].split(",")
    # the numeric CSV columns, each once (the CSV repeats a listed quantity that is a coordinate: q9, F1),
    # then the configuration masks
    assert list(columns)[:-1] == list(dict.fromkeys(header[:-2]))
    assert np.array_equal(columns["F1 (lbf)"], result.contact_force("F1"))
    assert np.array_equal(result.contact_force("cam"), result.contact_force("F1"))
    assert np.allclose(columns["cam_angle (deg)"], np.arange(31.0), rtol=0, atol=1e-9)  # one row a degree
    # the CSV's numbers are these arrays to its 10 significant digits
    first = [float(v) for v in text.splitlines()[5].split(",")[:len(header) - 2]]
    assert np.allclose(first, [columns[name][4] for name in header[:-2]], rtol=1e-9, atol=0)


def test_a_bad_override_or_name_is_one_input_error() -> None:
    import vtool
    from vtool.errors import InputError

    model = vtool.load("gnilka-1a")
    with pytest.raises(InputError, match="members.valve_spring.stiffness"):
        model.set({"members.valve_spring.stiffness": -1.0})
    with pytest.raises(InputError, match="backend"):
        model.set(degrees=10.0).solve(backend="euler")
    with pytest.raises(InputError, match="one of: cam, rocker, seat"):
        model.set(degrees=10.0).solve().contact_force("tappet")
    with pytest.raises(InputError, match="valvetrain"):
        vtool.load("boom-brick-wall").solve()


def test_a_model_from_a_dict_is_the_preset() -> None:
    import vtool

    model = vtool.load("gnilka-1d")
    rebuilt = vtool.load(model.document)
    assert rebuilt.spec == model.spec
    model.document["run"]["rpm"] = 1.0  # the rebuilt model took a copy
    assert rebuilt.spec.run.rpm == 11000.0


def test_sweep_arrays_match_single_runs() -> None:
    import vtool

    model = vtool.load("gnilka-1d").set(degrees=400.0)
    study = model.sweep({"run.rpm": [9000.0, 10000.0]})
    assert list(study.values("run.rpm")) == [9000.0, 10000.0]
    for rpm, peak in zip(study.values("run.rpm"), study.metric("peak_F1"), strict=True):
        assert peak == model.set(rpm=float(rpm)).solve().metrics()["peak_F1"]


def test_to_dataframe_needs_pandas_and_says_so() -> None:
    import vtool

    result = vtool.load("gnilka-1a").set(degrees=5.0).solve()
    try:
        import pandas  # noqa: F401
    except ImportError:
        with pytest.raises(ImportError, match="needs pandas"):
            result.to_dataframe()
    else:
        frame = result.to_dataframe()
        assert list(frame.columns) == list(result.arrays())
        assert np.array_equal(frame["F1 (lbf)"].to_numpy(), result.contact_force("F1"))
