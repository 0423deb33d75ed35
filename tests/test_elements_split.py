"""Members split into equal elements (solvers/model/assembly.py: sub_elements, split_members).

Sources: a fixed-free uniform bar of stiffness k = EA/L and mass m has
ω_1 = (π/2) sqrt(k/m); consistent-mass linear bar elements over-estimate it
with an error ~ (ω h)² / 24 ∝ h², so the observed order from a log-log fit is
2 (Cook et al., Concepts and Applications of FEA, ch. 11). A cantilever
Euler-Bernoulli beam has ω_1 = 1.87510² sqrt(EI / (m L³)); Hermite cubic
elements with consistent mass converge at O(h⁴).
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import scipy.linalg

from vtool.presets import PRESET_DIR, load_document, load_preset, read_document
from vtool.presets.valvetrain import dump, load
from vtool.solvers.model.assembly import assemble_full
from vtool.solvers.model.mechanism import assemble

K_SPRING, M_SPRING = 254.0, 1.0e-4  # lbf/in, lbf s²/in


def single_member_doc(member: dict, n_coordinates: int) -> dict:
    """A mechanism of one member grounded at end a; the cam touches coordinate 1."""
    return {
        "kind": "valvetrain", "title": "one member", "units": "in-lbf-s",
        "coordinates": [{"name": f"c{i}", "motion": "translation" if i == 1 else "rotation"}
                        for i in range(1, n_coordinates + 1)],
        "members": {"m": member},
        "cam": {"coordinate": n_coordinates + 1, "amplitude": 0.1},
        "clearances": [{"name": "cam", "ahead": 1, "behind": n_coordinates + 1, "kind": "external"}],
        "initial": {"closed": ["cam"], "spring_preload": 1.0, "lever_ratio": 1.0},
        "run": {"rpm": 1000.0, "degrees": 10.0, "time_step": 1e-5},
    }


def lowest_omega(spec) -> float:  # type: ignore[no-untyped-def]
    M, K = assemble_full(spec)
    return float(np.sqrt(scipy.linalg.eigh(K, M, eigvals_only=True)[0]))


def observed_order(ns: list[int], errors: list[float]) -> float:
    return float(np.polyfit(np.log(1.0 / np.array(ns)), np.log(errors), 1)[0])


def test_fixed_free_bar_converges_at_second_order() -> None:
    exact = 0.5 * math.pi * math.sqrt(K_SPRING / M_SPRING)
    ns = [2, 4, 8, 16, 32]
    errors = []
    for n in ns:
        member = {"element": "bar", "length": 36.0, "stiffness": K_SPRING, "mass": M_SPRING,
                  "coordinates": [0, 1], "elements": n}
        omega = lowest_omega(load(single_member_doc(member, 1)))
        assert omega > exact  # consistent mass: an upper bound
        errors.append(omega / exact - 1.0)
    assert observed_order(ns, errors) == pytest.approx(2.0, abs=0.05)
    assert errors[-1] < 1e-3


def test_cantilever_beam_converges_at_fourth_order() -> None:
    EI, L, m = 30.0e6 * math.pi * 0.6**4 / 64, 2.5, 0.02
    exact = 1.8751040687**2 * math.sqrt(EI / (m * L**3))
    ns = [1, 2, 4, 8]
    errors = []
    for n in ns:
        member = {"element": "beam", "length": L, "diameter": 0.6, "modulus": 30.0e6, "mass": m,
                  "coordinates": [0, 1, 0, 2], "elements": n}
        errors.append(lowest_omega(load(single_member_doc(member, 2))) / exact - 1.0)
    assert observed_order(ns, errors) == pytest.approx(4.0, abs=0.3)


def test_one_element_is_the_thesis_model() -> None:
    doc = copy.deepcopy(read_document(PRESET_DIR / "gnilka-1a.toml"))
    doc["members"]["valve_spring"]["elements"] = 1
    split, thesis = load_document(doc), load_preset("gnilka-1a")
    assert split == thesis
    np.testing.assert_array_equal(assemble_full(split)[0], assemble_full(thesis)[0])


def split_1a(**elements: int):  # type: ignore[no-untyped-def]
    doc = copy.deepcopy(read_document(PRESET_DIR / "gnilka-1a.toml"))
    for name, n in elements.items():
        doc["members"][name]["elements"] = n
    return load_document(doc)


def test_split_numbering_round_trips_to_the_preset_numbers() -> None:
    spec = split_1a(valve_spring=4, left_rocker=2)
    added = 3 + 2  # three spring nodes, one beam node (deflection, rotation)
    assert spec.n_coordinates == 8 + added
    assert [c.name for c in spec.coordinates[8:]] == [
        "left_rocker node 1", "left_rocker node 1 rotation",
        "valve_spring node 1", "valve_spring node 2", "valve_spring node 3"]
    assert spec.cam.coordinate == 9 + added and spec.seat.coordinate == 10 + added
    assert spec.clearance("cam").behind == 9 + added and spec.clearance("rocker").behind == 8
    assert spec.run.quantities[:3] == ("q1-q14", "q2-q8", "q14")
    doc = dump(spec)
    assert doc["cam"]["coordinate"] == 9 and doc["run"]["quantities"][:3] == ["q1-q9", "q2-q8", "q9"]
    assert len(doc["coordinates"]) == 8 and doc["members"]["valve_spring"]["elements"] == 4
    assert load(doc) == spec


def test_split_spring_adds_surge_modes_near_the_fixed_fixed_bar() -> None:
    """The valve end of the spring is held by the valve train (much stiffer, heavier), so the
    spring's first surge mode lies near the fixed-fixed bar's π sqrt(k/m)."""
    spec = split_1a(valve_spring=8)
    mass = 0.283 / 386.0 * math.pi * 0.07**2 / 4 * 36.0
    fixed_fixed = math.pi * math.sqrt(254.0 / mass)
    omegas = assemble(spec).start_layer.modes.omega
    thesis = assemble(load_preset("gnilka-1a")).start_layer.modes.omega
    assert omegas[0] == pytest.approx(thesis[0], rel=0.05)  # the valve-train fundamental stays
    surge = omegas[(omegas > 2 * thesis[0]) & (omegas < 3 * fixed_fixed)]
    assert surge[0] == pytest.approx(fixed_fixed, rel=0.1)


def test_modes_command_names_the_surge_modes(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from click.testing import CliRunner

    from vtool.app.cli.main import cli
    from vtool.presets import save_spec

    save_spec(split_1a(valve_spring=4), tmp_path / "split.toml")
    result = CliRunner().invoke(cli, ["modes", str(tmp_path / "split.toml")])
    assert result.exit_code == 0, result.output
    layer = result.output.split("Layer closed: rocker")[1].split("mode shapes")[0]
    assert layer.count("valve_spring surge") == 3
    fundamental = layer.splitlines()[2]
    assert "surge" not in fundamental


def test_per_mode_damping_follows_the_one_element_mode() -> None:
    """gnilka-1a gives 0.5 to mode 2 (25.9e3 rad/s) of the rocker-closed layer; split springs add
    surge modes below it, and the override stays with the 25.9e3 rad/s mode."""
    layer = assemble(split_1a(valve_spring=8)).layer({"rocker"})
    heavy = np.nonzero(layer.damping_ratios == 0.5)[0]
    assert len(heavy) == 1
    assert layer.modes.omega[heavy[0]] == pytest.approx(25.9e3, rel=0.03)
