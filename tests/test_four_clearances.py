"""A fourth clearance (thesis appendix C: valve-stem/rocker joint) is a preset change only."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from vtool.presets import PRESET_DIR, load_document, load_preset, read_document
from vtool.presets.valvetrain import dump
from vtool.solvers.model.layers import possible_layers
from vtool.solvers.model.mechanism import assemble


def four_clearance_doc(stem_state: str) -> dict:
    """Example 1A with the valve stem given its own top coordinate q9 and a clearance to q4."""
    doc = copy.deepcopy(read_document(PRESET_DIR / "gnilka-1a.toml"))
    doc["coordinates"].append({"name": "valve stem top", "motion": "translation"})
    doc["members"]["valve"]["coordinates"] = [-7, 9]
    doc["cam"]["coordinate"] = 10
    doc["seat"]["coordinate"] = 11
    for c in doc["clearances"]:
        c["behind"] = {9: 10, 10: 11}.get(c["behind"], c["behind"])
    doc["clearances"].append(
        {"name": "stem", "ahead": 9, "behind": 4, "kind": "internal", "state": stem_state, "restitution": 0.0}
    )
    doc["initial"]["closed"] = ["cam", "rocker", "stem"]
    doc["damping"]["layers"][1]["closed"] = ["rocker", "stem"]
    return doc


def test_enabled_fourth_clearance_gives_four_layers_and_sixteen_configurations() -> None:
    spec = load_document(four_clearance_doc("enabled"))
    assert len(spec.clearances) == 4
    assert 2 ** len(spec.clearances) == 16
    assert sorted(sorted(layer) for layer in possible_layers(spec)) == [
        [], ["rocker"], ["rocker", "stem"], ["stem"]
    ]


def test_pinned_fourth_clearance_reproduces_the_three_clearance_model() -> None:
    three = assemble(load_preset("gnilka-1a"))
    four = assemble(load_document(four_clearance_doc("pinned")))
    for closed in (frozenset(), frozenset({"rocker"})):
        a, b = three.layer(closed), four.layer(closed)
        np.testing.assert_allclose(b.M, a.M, rtol=1e-14, atol=1e-20)
        np.testing.assert_allclose(b.K, a.K, rtol=1e-14, atol=1e-6)
        np.testing.assert_allclose(b.modes.omega, a.modes.omega, rtol=1e-9, atol=1e-6)
    assert four.start.cam_offset == pytest.approx(three.start.cam_offset, rel=1e-12)
    assert four.start.follower_force == pytest.approx(three.start.follower_force, rel=1e-12)


def test_four_clearance_preset_round_trips() -> None:
    spec = load_document(four_clearance_doc("enabled"))
    assert load_document(dump(spec)) == spec
