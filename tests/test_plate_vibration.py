"""Assembled plate: constraint counts, frequencies against Navier, the thesis' claims.

Sources: thesis 001 Part II, section 2.3 (64 and 82 constrained DOF on the
4 × 4 grid; A6/B6 errors "four to five times" the original's; the centre
node alone "6 to 8 %"; B3 beats B5 and B6, and B4 except in the first two
modes; A3 does not beat A5/A6; A9 beats A10 on the first four modes),
Navier's solution (thesis eq. 41) and the classical centre deflection of a
uniformly loaded simply supported plate, α q b⁴/D with α = 0.00705 at
a/b = 1.4 and 0.00772 at 1.5 (Timoshenko & Woinowsky-Krieger, Table 8).
"""

from __future__ import annotations

import numpy as np
import pytest

from vtool.assessments.plate.assembly import Plate, make_mesh
from vtool.assessments.plate.constraints import free_dofs, restrict
from vtool.assessments.plate.exact import lowest_modes, navier_frequency, static_deflection
from vtool.assessments.plate.model import Case, MasterSelection, build_model
from vtool.assessments.plate.vibration import convergence_order, free_vibration

PLATE = Plate(40.0, 27.0, 0.1, 30.0e6, 0.3, 0.283 / 386.0)


def _errors(element: str, masters: str, n: int = 4, count: int = 6) -> np.ndarray:
    case = Case("x", element, n, n, MasterSelection(named=masters))
    return free_vibration(PLATE, build_model(PLATE, case), count).errors_pct


@pytest.mark.parametrize(("element", "expected"), [("bfs16", 64), ("mason24", 82)])
def test_constrained_dof_counts_on_the_thesis_grid(element: str, expected: int) -> None:
    assert free_dofs(make_mesh(PLATE, element, 4, 4)).size == expected


@pytest.mark.parametrize("n", [1, 2, 3, 5])
def test_constrained_dof_count_formulas(n: int) -> None:
    nodes = (n + 1) ** 2
    edge, corners = 4 * (n - 1), 4
    assert free_dofs(make_mesh(PLATE, "bfs16", n, n)).size == 4 * nodes - 2 * edge - 3 * corners
    assert free_dofs(make_mesh(PLATE, "mason24", n, n)).size == 6 * nodes - 4 * edge - 5 * corners


def test_full_16_dof_model_fundamental_error() -> None:
    errors = _errors("bfs16", "all")
    assert 0.010 < errors[0] < 0.020  # thesis A1: about 0.015 %
    assert np.all(errors > 0)  # conforming elements bound frequencies from above


@pytest.mark.parametrize(("element", "low", "high"), [("bfs16", 3.7, 4.3), ("mason24", 1.5, 2.5)])
def test_observed_convergence_order(element: str, low: float, high: float) -> None:
    """bicubic: eigenvalue error O(h⁴); the 24-DOF element lacks x²y, xy² (order ≈ 2)."""
    meshes = np.array([2, 4, 8])
    errs = [_errors(element, "all", int(n), 1)[0] for n in meshes]
    order = convergence_order(1.0 / meshes, np.array(errs))
    assert low < order < high


@pytest.mark.parametrize("element", ["bfs16", "mason24"])
def test_w_at_interior_nodes_is_four_to_five_times_the_full_error(element: str) -> None:
    ratio = _errors(element, "interior-w")[0] / _errors(element, "all")[0]
    assert 3.5 < ratio < 5.5


@pytest.mark.parametrize("element", ["bfs16", "mason24"])
def test_centre_node_alone_six_to_eight_percent(element: str) -> None:
    assert 6.0 < _errors(element, "centre-w", count=1)[0] < 8.0


def test_coarser_24_dof_mesh_beats_reduced_finer_models() -> None:
    b3 = _errors("mason24", "all", n=2)  # 18 DOF
    b4 = _errors("mason24", "interior-all")  # 54 DOF
    b5 = _errors("mason24", "interior-w-slopes")  # 27 DOF
    b6 = _errors("mason24", "interior-w")  # 9 DOF
    assert np.all(b3 < b5) and np.all(b3 < b6)
    assert np.all(b3[:2] > b4[:2]) and np.all(b3[2:] < b4[2:])  # "apart from the first and second"


def test_coarser_16_dof_mesh_does_not_beat_reduced_finer_models() -> None:
    a3 = _errors("bfs16", "all", n=2)  # 16 DOF
    assert np.all(a3 > _errors("bfs16", "interior-w-slopes"))
    assert np.all(a3[:4] > _errors("bfs16", "interior-w")[:4])


@pytest.mark.parametrize("element", ["bfs16", "mason24"])
def test_eliminate_least_flexible_nodes_first(element: str) -> None:
    plus = _errors(element, "five-plus-w", count=4)
    cross = _errors(element, "five-cross-w", count=4)
    assert np.all(plus <= cross + 1e-9) and plus[0] < cross[0] and plus[3] < cross[3]


def test_navier_frequencies_and_ordering() -> None:
    D = PLATE.rigidity
    w11 = np.pi**2 * (1 / 40.0**2 + 1 / 27.0**2) * np.sqrt(D / PLATE.mass_per_area)
    assert navier_frequency(PLATE, 1, 1) == pytest.approx(w11, rel=1e-14)
    modes = lowest_modes(PLATE, 60)
    brute = sorted(navier_frequency(PLATE, m, n) for m in range(1, 40) for n in range(1, 40))[:60]
    assert [md.omega for md in modes] == pytest.approx(brute, rel=1e-14)
    assert [(md.m, md.n) for md in modes[:4]] == [(1, 1), (2, 1), (1, 2), (3, 1)]


def test_static_centre_deflection_classical_value() -> None:
    """Uniform q: w = α q b⁴/D, b = 27 the short side, a/b = 1.481; α ≈ 0.0076."""
    alpha = static_deflection(PLATE, "uniform") * PLATE.rigidity / 27.0**4
    lo, hi = 0.00705, 0.00772
    interpolated = lo + (hi - lo) * (40.0 / 27.0 - 1.4) / 0.1
    assert alpha == pytest.approx(interpolated, rel=0.01)
    assert alpha == pytest.approx(0.0076, abs=0.00005)


@pytest.mark.parametrize(("load", "n", "rel"), [("uniform", 8, 2e-4), ("point", 16, 1.5e-3)])
def test_finite_element_static_deflection_matches_navier(load: str, n: int, rel: float) -> None:
    """The point force converges more slowly (its moments are singular under the load)."""
    mesh = make_mesh(PLATE, "bfs16", n, n)
    M, K, f, free = restrict(mesh)
    e = mesh.point_vector(20.0, 13.5)[free]
    F = f if load == "uniform" else e
    w = e @ np.linalg.solve(K, F)
    assert w == pytest.approx(static_deflection(PLATE, load, 16000), rel=rel)
