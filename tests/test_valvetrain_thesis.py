"""The valve-train model reproduces Gnilka (1971)'s printed frequencies, matrices and start."""

from __future__ import annotations

import numpy as np
import pytest

from tests import thesis_data as thesis
from vtool.presets import load_preset
from vtool.solvers.model.mechanism import assemble


def agrees_to_printed_digits(ours: np.ndarray, printed: np.ndarray, scale: float) -> np.ndarray:
    """True where ours rounds to the printed three significant digits.

    Printed zeros must be zero to 1e-9 of the matrix scale.
    """
    tol = np.where(printed == 0.0, 1e-9 * scale, 0.0051 * np.abs(printed))
    return np.abs(ours - printed) <= tol


@pytest.fixture(scope="module")
def mechanism_1a():
    return assemble(load_preset("gnilka-1a"))


def test_rocker_open_frequencies_match_fig_6_1(mechanism_1a) -> None:
    omega = mechanism_1a.layer(frozenset()).modes.omega
    assert omega[0] == 0.0  # the free pushrod's rigid-body mode
    np.testing.assert_allclose(omega[1:], thesis.FIG_6_1_OMEGA[1:], rtol=0.002)


def test_rocker_contact_frequencies_match_fig_6_2(mechanism_1a) -> None:
    omega = mechanism_1a.layer({"rocker"}).modes.omega
    np.testing.assert_allclose(omega, thesis.FIG_6_2_OMEGA, rtol=0.002)


def test_first_reduced_mode_shape_matches_fig_6_2(mechanism_1a) -> None:
    shape = mechanism_1a.layer({"rocker"}).modes.shapes[:, 0]
    shape = shape * np.sign(shape[0])
    np.testing.assert_allclose(shape, thesis.FIG_6_2_MODE_1, rtol=0.002, atol=0.01)


@pytest.mark.parametrize("which", ["M", "K"])
def test_rocker_contact_mass_and_stiffness_match_fig_6_8(mechanism_1a, which: str) -> None:
    layer = mechanism_1a.layer({"rocker"})
    ours = getattr(layer, which)
    printed = getattr(thesis, f"FIG_6_8_{which}")
    ok = agrees_to_printed_digits(ours, printed, np.abs(printed).max())
    assert ok.all(), f"{which} differs at {np.argwhere(~ok).tolist()}"


def test_rocker_contact_damping_matches_fig_6_8(mechanism_1a) -> None:
    C = mechanism_1a.layer({"rocker"}).C
    upper = np.triu(np.ones_like(C, dtype=bool))
    printed = thesis.FIG_6_8_C_UPPER
    ok = agrees_to_printed_digits(C, printed, 1.0) | ~upper
    assert ok.all(), f"C differs at {np.argwhere(~ok).tolist()}"


def test_rocker_open_damping_matches_figs_6_13_to_6_16(mechanism_1a) -> None:
    C = mechanism_1a.layer(frozenset()).C  # coordinates q1..q8
    block = C[1:7, 1:7]
    upper = np.triu(np.ones_like(block, dtype=bool))
    ok = agrees_to_printed_digits(block, thesis.FIG_6_13_C_UPPER_Q2_Q7, 1.0) | ~upper
    assert ok.all(), f"C differs at {np.argwhere(~ok).tolist()}"
    assert C[7, 7] == pytest.approx(thesis.FIG_6_16_C_Q8_Q8, rel=0.0051)
    assert C[7, 0] == pytest.approx(thesis.FIG_6_14_C_Q8_Q1, rel=0.0051)
    # the free pushrod is decoupled from the rocker when the rocker is open
    assert np.abs(C[0, 1:7]).max() < 1e-9


def test_prose_damping_rule_does_not_reproduce_the_printed_matrix(mechanism_1a) -> None:
    """The prose's rule (0.5 on the fundamental) is not what the thesis printed."""
    from vtool.solvers.model.damping import modal_damping

    layer = mechanism_1a.layer({"rocker"})
    prose = np.full(layer.size, 0.1)
    prose[0] = 0.5
    C = modal_damping(layer.M, layer.modes, prose)
    assert not agrees_to_printed_digits(C, thesis.FIG_6_8_C_UPPER, 1.0)[0, 0]


def test_static_start_matches_appendix_e_printout(mechanism_1a) -> None:
    start = mechanism_1a.start
    assert float(f"{start.cam_offset:.6g}") == float(f"{thesis.XZERO:.6g}")
    assert float(f"{start.follower_force:.6g}") == float(f"{thesis.FZERO:.6g}")
    assert start.q[0] == pytest.approx(start.cam_offset, rel=1e-12)
    assert start.q[1] == pytest.approx(start.q[7], rel=1e-12)  # rocker closed: q2 = q8


def test_prose_spring_rate_does_not_reproduce_the_tables() -> None:
    """With the prose's 245 lbf/in the two lowest frequencies miss the printed ones."""
    import dataclasses

    spec = load_preset("gnilka-1a")
    members = tuple(
        dataclasses.replace(m, stiffness=245.0) if m.name == "valve_spring" else m for m in spec.members
    )
    omega = assemble(dataclasses.replace(spec, members=members)).layer({"rocker"}).modes.omega
    assert abs(omega[0] / thesis.FIG_6_2_OMEGA[0] - 1) > 0.01


@pytest.mark.parametrize("name", ["gnilka-1c", "gnilka-1d"])
def test_pinned_rocker_has_only_the_contact_layer(name: str) -> None:
    mechanism = assemble(load_preset(name))
    layers = mechanism.all_layers()
    assert [sorted(layer.closed) for layer in layers] == [["rocker"]]
    np.testing.assert_allclose(layers[0].modes.omega, thesis.FIG_6_2_OMEGA, rtol=0.002)


@pytest.mark.parametrize("name", ["gnilka-1a", "gnilka-2", "gnilka-3"])
def test_modes_by_cholesky_reduction_match_lapack_generalized_eigh(name: str) -> None:
    """undamped_modes reduces K φ = ω² M φ with NumPy (no scipy.linalg on the solve path); it agrees
    with LAPACK's generalized solver (scipy.linalg.eigh) in every contact layer: frequencies to 1e-9
    relative of the highest, mass-normalised shapes (Φᵀ M Φ = I) up to sign."""
    import scipy.linalg

    from vtool.solvers.model.damping import undamped_modes

    mechanism = assemble(load_preset(name))
    spec = mechanism.spec
    internal = [c.name for c in spec.clearances if c.kind == "internal" and c.state == "enabled"]
    for closed in [frozenset(), *(frozenset([c]) for c in internal)]:
        layer = mechanism.layer(closed)
        modes = undamped_modes(layer.M, layer.K)
        w2, shapes = scipy.linalg.eigh(layer.K, layer.M)
        omega = np.sqrt(np.clip(w2, 0.0, None))
        assert np.abs(modes.omega - omega).max() <= 1e-9 * omega.max()
        np.testing.assert_allclose(modes.shapes.T @ layer.M @ modes.shapes, np.eye(len(omega)), atol=1e-10)
        distinct = np.abs(np.diff(omega)) > 1e-6 * omega.max()
        for j in range(len(omega)):
            if (j == 0 or distinct[j - 1]) and (j == len(omega) - 1 or distinct[j]):
                phi, ref = modes.shapes[:, j], shapes[:, j]
                assert min(np.abs(phi - ref).max(), np.abs(phi + ref).max()) <= 1e-7 * np.abs(ref).max()
