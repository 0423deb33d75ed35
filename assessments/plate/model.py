"""A case (plate, element, mesh, master set, reduction) turned into its reduced model.

``build_model`` runs the chain element matrices → assembly → simply
supported constraints → T (Guyan, IRS or identity) → ``reduce(T)`` and keeps
what the free-vibration and transient checks need: the reduced matrices,
the reduced loads of a unit uniform pressure and of a unit point force at
the centre, and the row that recovers the centre deflection from the
masters.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from vtool.assessments.plate.assembly import Mesh, Plate, make_mesh
from vtool.assessments.plate.constraints import restrict
from vtool.assessments.plate.masters import MasterSetError, labelled_set, named_set
from vtool.assessments.plate.reduction import guyan_T, henshell_ong_masters, irs_T, reduce
from vtool.errors import RunError
from vtool.threads import limited

METHODS = ("guyan", "irs")


@dataclass(frozen=True)
class MasterSelection:
    """How masters are chosen: a named set, explicit labels, or Henshell–Ong with a count."""

    named: str | None = None
    labels: tuple[str, ...] = ()
    auto: int | None = None

    def __post_init__(self) -> None:
        given = sum([self.named is not None, bool(self.labels), self.auto is not None])
        if given != 1:
            raise ValueError("MasterSelection: give exactly one of named, labels, auto")

    def describe(self) -> str:
        from vtool.assessments.plate.masters import NAMED_SETS

        if self.named is not None:
            return NAMED_SETS[self.named].description if self.named in NAMED_SETS else self.named
        if self.labels:
            return "user set: " + " ".join(self.labels)
        return f"Henshell-Ong: {self.auto} masters, largest k/m eliminated first"


@dataclass(frozen=True)
class Case:
    """One line of the thesis' tables: element, mesh, masters and reduction method."""

    name: str
    element: str
    nx: int
    ny: int
    masters: MasterSelection
    method: str = "guyan"
    note: str = ""


@dataclass(frozen=True)
class ReducedModel:
    """The reduced system M_R q̈ + K_R q = F_R and how to read the plate back from q.

    ``T`` maps masters q to the free (unconstrained) DOFs of the mesh;
    ``centre_row @ q`` is the centre deflection; ``f_uniform`` and
    ``f_point`` are the reduced loads of p0 = 1 and of P = 1 at the centre.
    """

    case: Case
    mesh: Mesh
    free: np.ndarray
    masters: np.ndarray
    T: np.ndarray
    M: np.ndarray
    K: np.ndarray
    f_uniform: np.ndarray
    f_point: np.ndarray
    centre_row: np.ndarray
    full_size: int
    build_seconds: float

    @property
    def size(self) -> int:
        """KS: the number of master unknowns."""
        return self.M.shape[0]

    def master_labels(self) -> list[str]:
        return [self.mesh.dof_label(int(self.free[k])) for k in self.masters]


def master_positions(mesh: Mesh, selection: MasterSelection, free: np.ndarray,
                     M_c: np.ndarray | None = None, K_c: np.ndarray | None = None) -> np.ndarray:
    """Positions (into ``free``) of the masters a selection picks."""
    if selection.named is not None:
        return named_set(mesh, selection.named, free)
    if selection.labels:
        return labelled_set(mesh, selection.labels, free)
    if not 1 <= int(selection.auto) <= free.size:  # type: ignore[arg-type]  # an automatic selection here: named and labels were not given
        raise MasterSetError(f"automatic selection needs 1..{free.size} masters (got {selection.auto})")
    assert M_c is not None and K_c is not None
    return henshell_ong_masters(M_c, K_c, int(selection.auto))  # type: ignore[arg-type]  # an automatic selection here: named and labels were not given


@limited()  # small dense matrices: one BLAS thread (vtool.threads)
def build_model(plate: Plate, case: Case) -> ReducedModel:
    """Assemble, constrain and reduce one case."""
    start = time.perf_counter()
    mesh = make_mesh(plate, case.element, case.nx, case.ny)
    M_c, K_c, f_c, free = restrict(mesh)
    masters = master_positions(mesh, case.masters, free, M_c, K_c)
    if case.method not in METHODS:
        raise ValueError(f"method: {case.method!r} is not one of: {', '.join(METHODS)}")
    try:
        if masters.size == free.size:
            T = np.eye(free.size)
        elif case.method == "irs":
            T = irs_T(M_c, K_c, masters)
        else:
            T = guyan_T(K_c, masters)
    except np.linalg.LinAlgError as exc:
        raise RunError(f"case {case.name}: the reduction failed ({exc}); the stiffness is not "
                       "positive definite in floating point (check thickness, youngs_modulus, "
                       "a, b and the mesh)") from None
    if not (np.all(np.isfinite(T)) and np.all(np.isfinite(K_c)) and np.all(np.isfinite(M_c))):
        raise RunError(f"case {case.name}: non-finite stiffness or mass (check thickness, "
                       "youngs_modulus, density, a, b)")
    e_centre = mesh.point_vector(plate.a / 2.0, plate.b / 2.0)[free]
    M_R, K_R, f_R = reduce(M_c, K_c, f_c, T)
    centre_row = e_centre @ T
    return ReducedModel(
        case=case, mesh=mesh, free=free, masters=masters, T=T, M=M_R, K=K_R,
        f_uniform=f_R, f_point=T.T @ e_centre, centre_row=centre_row,
        full_size=free.size, build_seconds=time.perf_counter() - start,
    )
