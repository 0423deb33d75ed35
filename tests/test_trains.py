"""Train types (presets/trains.py): the ohv-pushrod type reproduces gnilka-1a; expansion; field errors."""

from __future__ import annotations

import numpy as np
import pytest

from vtool.errors import InputError
from vtool.presets import load_document, load_preset, read_document
from vtool.presets.trains import expand
from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.run import simulate


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.abs(a - b).max() / np.abs(b).max())


def test_ohv_pushrod_type_equals_gnilka_1a_matrices() -> None:
    thesis, train = Mechanism(load_preset("gnilka-1a")), Mechanism(load_preset("ohv-pushrod-1a"))
    assert _relative(train.M, thesis.M) <= 1e-12 and _relative(train.K, thesis.K) <= 1e-12
    for closed in (frozenset(), frozenset({"rocker"})):
        ours, theirs = train.layer(closed), thesis.layer(closed)
        for name in ("M", "K", "C"):
            assert _relative(getattr(ours, name), getattr(theirs, name)) <= 1e-12, (closed, name)


def test_ohv_pushrod_type_gives_gnilka_1a_events() -> None:
    thesis, train = simulate(load_preset("gnilka-1a")), simulate(load_preset("ohv-pushrod-1a"))
    assert len(thesis.events) > 5
    assert [(e.clearance, e.kind, e.before, e.after) for e in train.events] == \
        [(e.clearance, e.kind, e.before, e.after) for e in thesis.events]
    np.testing.assert_allclose([e.cam_angle for e in train.events], [e.cam_angle for e in thesis.events],
                               rtol=0, atol=1e-9)


def _doc(name: str) -> dict:
    from vtool.presets import find_preset

    return read_document(find_preset(name))


def test_expanded_form_loads_to_the_same_spec() -> None:
    import tomllib

    import tomli_w

    doc = _doc("ohv-pushrod-1a")
    explicit = tomllib.loads(tomli_w.dumps(expand(doc)))
    assert "train" not in explicit and "members" in explicit
    assert load_document(explicit) == load_document(doc)


@pytest.mark.parametrize(("path", "value", "field"), [
    (("train", "type"), "ohc", "train.type"),
    (("train", "rocker", "cam_arm"), -1.0, "train.rocker.cam_arm"),
    (("train", "spring", "rate"), 0.0, "train.spring.rate"),
    (("train", "cam", "law"), "sine", "train.cam.law"),
    (("train", "pushrod", "lenght"), 9.0, "train.pushrod.lenght"),
])
def test_bad_train_fields_name_the_field(path: tuple[str, ...], value: object, field: str) -> None:
    doc = _doc("ohv-pushrod-1a")
    table = doc
    for key in path[:-1]:
        table = table[key]
    table[path[-1]] = value
    with pytest.raises(InputError) as error:
        load_document(doc)
    assert error.value.field == field


def test_explicit_tables_beside_a_train_are_refused() -> None:
    doc = _doc("ohv-pushrod-1a") | {"members": {}}
    with pytest.raises(InputError, match="members"):
        load_document(doc)
