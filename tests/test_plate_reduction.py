"""Reduction: Guyan/Irons properties, IRS, Henshell–Ong, against textbook versions.

Properties (Guyan 1965; Irons 1965; O'Callaghan 1989 for IRS): static
condensation is exact for loads applied at masters; it is a Rayleigh–Ritz
projection, so each reduced eigenvalue bounds the full one from above; the
reduced matrices stay symmetric positive definite. The thesis' eqs. (34)–(36)
eliminate one slave at a time; the test re-implements that loop as the plain
reference for ``guyan_T`` + ``reduce``.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sla
from hypothesis import given, settings
from hypothesis import strategies as st

from vtool.assessments.plate.assembly import Plate, make_mesh
from vtool.assessments.plate.constraints import restrict
from vtool.assessments.plate.model import Case, MasterSelection, build_model
from vtool.assessments.plate.reduction import guyan_T, henshell_ong_masters, irs_T, reduce
from vtool.assessments.plate.vibration import free_vibration, natural_frequencies

PLATE = Plate(40.0, 27.0, 0.1, 30.0e6, 0.3, 0.283 / 386.0)
M16, K16, F16, FREE16 = restrict(make_mesh(PLATE, "bfs16", 4, 4))
M24, K24, F24, FREE24 = restrict(make_mesh(PLATE, "mason24", 2, 2))


def irons_one_at_a_time(M, K, F, slaves):
    """Thesis eqs. (34)-(36): eliminate each slave s in turn from M, K, F."""
    M, K, F = M.copy(), K.copy(), F.copy()
    index = list(range(K.shape[0]))
    for s_orig in sorted(slaves, reverse=True):
        s = index.index(s_orig)
        keep = [i for i in range(K.shape[0]) if i != s]
        r = K[keep, s] / K[s, s]
        F = F[keep] - F[s] * r
        Mn = M[np.ix_(keep, keep)] - np.outer(M[keep, s], r) - np.outer(r, M[s, keep]) + M[s, s] * np.outer(r, r)
        K = K[np.ix_(keep, keep)] - np.outer(r, K[s, keep])
        M = Mn
        del index[s]
    return M, K, F


masters_strategy = st.lists(st.integers(0, 63), min_size=1, max_size=20, unique=True)


@given(masters=masters_strategy)
@settings(max_examples=30, deadline=None)
def test_guyan_equals_irons_sequential_elimination(masters) -> None:
    m = np.array(sorted(masters))
    slaves = np.setdiff1d(np.arange(64), m)
    MR, KR, FR = reduce(M16, K16, F16, guyan_T(K16, m))
    Mi, Ki, Fi = irons_one_at_a_time(M16, K16, F16, slaves)
    assert np.allclose(KR, Ki, rtol=1e-8, atol=1e-8 * np.abs(K16).max())
    assert np.allclose(MR, Mi, rtol=1e-8, atol=1e-8 * np.abs(M16).max())
    assert np.allclose(FR, Fi, rtol=1e-8, atol=1e-8 * np.abs(F16).max())


@given(masters=masters_strategy, data=st.data())
@settings(max_examples=30, deadline=None)
def test_guyan_is_exact_for_static_loads_at_masters(masters, data) -> None:
    m = np.array(sorted(masters))
    loads = data.draw(st.lists(st.floats(-1e3, 1e3), min_size=m.size, max_size=m.size))
    F = np.zeros(64)
    F[m] = loads
    T = guyan_T(K16, m)
    _, KR, FR = reduce(M16, K16, F, T)
    u_full = np.linalg.solve(K16, F)
    u_red = T @ np.linalg.solve(KR, FR)
    assert np.allclose(u_red, u_full, rtol=1e-7, atol=1e-9 * np.abs(u_full).max() + 1e-300)


@pytest.mark.parametrize(("M", "K", "F", "n"), [(M16, K16, F16, 64), (M24, K24, F24, 18)], ids=["bfs16", "mason24"])
@given(data=st.data())
@settings(max_examples=25, deadline=None)
def test_reduced_frequencies_bound_full_and_matrices_spd(M, K, F, n, data) -> None:
    m = np.array(sorted(data.draw(st.lists(st.integers(0, n - 1), min_size=1, max_size=n, unique=True))))
    full = natural_frequencies(M, K)
    for T in (guyan_T(K, m), irs_T(M, K, m)):
        MR, KR, _ = reduce(M, K, F, T)
        assert np.array_equal(MR, MR.T) and np.array_equal(KR, KR.T)
        assert np.linalg.eigvalsh(MR).min() > 0 and np.linalg.eigvalsh(KR).min() > 0
        red = natural_frequencies(MR, KR)
        assert np.all(red >= full[: red.size] * (1 - 1e-9))


def test_irs_improves_on_guyan_for_the_same_masters() -> None:
    for masters in ("interior-w", "five-plus-w", "centre-w"):
        g = build_model(PLATE, Case("g", "bfs16", 4, 4, MasterSelection(named=masters)))
        i = build_model(PLATE, Case("i", "bfs16", 4, 4, MasterSelection(named=masters), method="irs"))
        eg = free_vibration(PLATE, g, 1).fundamental_error_pct
        ei = free_vibration(PLATE, i, 1).fundamental_error_pct
        assert 0 <= ei < eg / 2


def test_henshell_ong_eliminates_largest_k_over_m_first() -> None:
    ratio = np.diag(K16) / np.diag(M16)
    kept = henshell_ong_masters(M16, K16, 63)
    assert np.setdiff1d(np.arange(64), kept).tolist() == [int(np.argmax(ratio))]


def test_henshell_ong_matches_reference_loop() -> None:
    """Plain reference: recompute the Guyan-reduced K, M of the survivors at every step."""
    alive = list(range(M16.shape[0]))
    M, K = M16, K16
    while len(alive) > 6:
        T = guyan_T(K, np.array(alive))
        MR, KR, _ = reduce(M, K, np.zeros(K.shape[0]), T)
        worst = int(np.argmax(np.diag(KR) / np.diag(MR)))
        del alive[worst]
    assert henshell_ong_masters(M, K, 6).tolist() == alive


def test_henshell_ong_nine_masters_finds_interior_deflections() -> None:
    """On the 4 × 4 grid, 9 automatic masters are the thesis' case A6 (w at interior nodes)."""
    model = build_model(PLATE, Case("h", "bfs16", 4, 4, MasterSelection(auto=9)))
    assert sorted(model.master_labels()) == sorted(f"w@{i},{j}" for i in (1, 2, 3) for j in (1, 2, 3))


def test_reduce_symmetrizes() -> None:
    rng = np.random.default_rng(1)
    T = rng.normal(size=(64, 7))
    MR, KR, FR = reduce(M16, K16, F16, T)
    assert np.array_equal(KR, KR.T) and np.array_equal(MR, MR.T)
    assert np.allclose(FR, T.T @ F16)
    assert np.allclose(KR, T.T @ K16 @ T, rtol=1e-10, atol=1e-10 * np.abs(KR).max())


def test_guyan_rejects_bad_master_indices() -> None:
    with pytest.raises(ValueError):
        guyan_T(K16, np.array([0, 0]))
    with pytest.raises(ValueError):
        guyan_T(K16, np.array([64]))
    with pytest.raises(ValueError):
        guyan_T(K16, np.array([], dtype=int))


def test_modal_frequencies_by_scipy_match_generalized_problem() -> None:
    lam = sla.eigvals(np.linalg.solve(M16, K16)).real
    assert np.allclose(np.sort(np.sqrt(lam)), natural_frequencies(M16, K16), rtol=1e-8)
