"""Element and system matrices: symmetry, definiteness, rigid-body modes, mass totals."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from vtool.presets import load_preset
from vtool.solvers.model.assembly import assemble_full, member_properties
from vtool.solvers.model.elements import bar_matrices, beam_matrices

positive = st.floats(min_value=1e-3, max_value=1e3, allow_nan=False)


def n_zero_eigenvalues(K: np.ndarray) -> int:
    eig = np.linalg.eigvalsh(K)
    return int(np.sum(np.abs(eig) <= 1e-9 * np.abs(eig).max()))


@given(k=positive, m=positive)
def test_bar_is_symmetric_psd_with_one_rigid_mode_and_right_mass(k: float, m: float) -> None:
    K, M = bar_matrices(k, m)
    assert np.array_equal(K, K.T) and np.array_equal(M, M.T)
    assert np.linalg.eigvalsh(K).min() >= -1e-12 * k
    assert np.linalg.eigvalsh(M).min() > 0
    assert n_zero_eigenvalues(K) == 1  # rigid translation
    translation = np.ones(2)
    assert abs(translation @ M @ translation - m) <= 1e-12 * m
    assert np.allclose(K @ translation, 0.0)


@given(EI=positive, L=positive, m=positive)
@settings(max_examples=60)
def test_beam_is_symmetric_psd_with_two_rigid_modes_and_right_mass(EI: float, L: float, m: float) -> None:
    K, M = beam_matrices(EI, L, m)
    assert np.allclose(K, K.T, rtol=0, atol=1e-12 * np.abs(K).max())
    assert np.allclose(M, M.T, rtol=0, atol=1e-12 * np.abs(M).max())
    assert np.linalg.eigvalsh(M).min() > 0
    # rigid translation (w = 1, theta = 0) and rigid rotation about end a (w_b = L, theta = 1)
    translation = np.array([1.0, 1.0, 0.0, 0.0])
    rotation = np.array([0.0, L, 1.0, 1.0])
    scale = np.abs(K).max()
    assert np.allclose(K @ translation, 0.0, atol=1e-9 * scale)
    assert np.allclose(K @ rotation, 0.0, atol=1e-9 * scale * max(L, 1.0))
    # exactly two zero eigenvalues: the nonzero ones are 12EI/L^3-ish, the zeros round-off
    eig = np.linalg.eigvalsh(K / scale)
    assert np.sum(eig < 1e-10) == 2 and eig.min() > -1e-10
    assert abs(translation @ M @ translation - m) <= 1e-12 * m


def test_system_matrices_symmetric_and_mass_positive_definite() -> None:
    spec = load_preset("gnilka-1a")
    M, K = assemble_full(spec)
    assert np.array_equal(M, M.T) and np.array_equal(K, K.T)
    assert np.linalg.eigvalsh(M).min() > 0
    # rocker open: the pushrod floats free, one rigid-body mode
    assert n_zero_eigenvalues(K) == 1


def test_system_mass_totals_equal_member_masses() -> None:
    """A unit translation of every translational end puts each bar's whole mass in motion."""
    spec = load_preset("gnilka-1a")
    M, _ = assemble_full(spec)
    pushrod = member_properties(next(m for m in spec.members if m.name == "pushrod"), spec.gravity)
    u = np.zeros(spec.n_coordinates)
    u[[0, 7]] = 1.0  # q1 and q8 move together: the pushrod translates rigidly
    assert abs(u @ M @ u - pushrod.mass) <= 1e-15
    assert abs(pushrod.mass - 0.283 * np.pi * 0.3**2 / 4 * 9.0 / 386.0) <= 1e-15
