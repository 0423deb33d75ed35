"""The exact back end is exact: against an augmented matrix exponential, closed forms, thread limits.

The reference propagation is written here: for y' = A y + B u(t) with the
Fourier basis u' = S u, the augmented state (y, u) obeys

    d/dt (y, u) = [[A, B], [0, S]] (y, u),

so (y, u)(t + τ) = expm([[A, B], [0, S]] τ) (y, u)(t) with scipy's expm and
no particular solution at all. In 1A's raw (x [in], v [in/s]) coordinates A
spans 1e3 to 1.4e6 rad/s and expm itself is only good to about 1e-8 (two
expm chains disagree by that much), so the reference takes the same expm in
energy coordinates z = (ω_i φ_iᵀ M x, φ_iᵀ M v) of the undamped modes, a
similarity transform built here from the configuration's M and K.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
import threadpoolctl
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.test_backends import base_excited_doc
from tests.valvetrain_cases import base_excited_response, spec_from
from vtool.errors import InputError, RunError
from vtool.presets import load_preset
from vtool.solvers.exact.backend import ExactOptions, _ExactRun, peak_brackets, safe_newton
from vtool.solvers.exact.statespace import state_space
from vtool.solvers.model.contact import ContactProblem
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.model.sources import SourceSeries
from vtool.solvers.scipy.backend import ScipyBackend, ScipyOptions
from vtool.solvers.trace import TraceBuilder
from vtool.threads import ENVIRONMENT, limited, thread_limit


def augmented(A: np.ndarray, B: np.ndarray, omega: float, tau: float) -> np.ndarray:
    """expm of [[A, B], [0, S]] τ, S the generator of u = (1, cos kωt.., sin kωt..)."""
    n, width = A.shape[0], B.shape[1]
    harmonics = (width - 1) // 2
    S = np.zeros((width, width))
    for k in range(1, harmonics + 1):
        S[k, harmonics + k] = -k * omega  # (cos kωt)' = -kω sin kωt
        S[harmonics + k, k] = k * omega  # (sin kωt)' = kω cos kωt
    big = np.zeros((n + width, n + width))
    big[:n, :n], big[:n, n:], big[n:, n:] = A, B, S
    return scipy.linalg.expm(big * tau)


def basis(omega: float, harmonics: int, t: float) -> np.ndarray:
    k = np.arange(1, harmonics + 1)
    return np.concatenate([[1.0], np.cos(k * omega * t), np.sin(k * omega * t)])


def energy_coordinates(M: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """z = T y with T = diag(Ω Φᵀ M, Φᵀ M) (Φᵀ M Φ = I); zero ω (rigid body) replaced by the lowest."""
    w2, Phi = scipy.linalg.eigh(K, M)
    omega = np.sqrt(np.clip(w2, w2[w2 > 1e-12 * w2.max()].min(), None))
    T = scipy.linalg.block_diag(omega[:, None] * (Phi.T @ M), Phi.T @ M)
    return T, scipy.linalg.block_diag(Phi / omega, Phi)


@pytest.fixture(scope="module")
def run_1a() -> _ExactRun:
    mechanism = assemble(load_preset("gnilka-1a"))
    problem = ContactProblem(mechanism)
    run = _ExactRun(problem, ExactOptions(output_interval=1.0),
                    TraceBuilder(mechanism.spec, problem.source_numbers, problem.omega))
    with limited():
        run.execute(None, None)
    return run


def test_exact_1a_equals_an_augmented_matrix_exponential_propagation(run_1a: _ExactRun) -> None:
    """Between events, every output state equals the augmented expm propagated (1° at a time) from
    the first output after the event, to 1e-10 relative: position errors relative to the largest
    |x| of the run, velocity errors to the largest |v| (an instant's own velocities pass near zero)."""
    run, layers = run_1a, run_1a.problem.tables.layers
    rows = [(float(t), q3, F, int(mask)) for block in run.builder.blocks for t, q3, F, mask in zip(*block, strict=True)]
    event_times = np.array(sorted(e.time for e in run.builder.events))
    n, dt = run.n, run.out_dt
    errors, previous, reference, step = [], None, None, {}
    for t, q3, _, mask in rows:
        x, v = q3[0], q3[1]
        ss = run.spaces[mask]
        y = run.state_of(ss, x[:n], v[:n])
        if mask not in step:
            layer, ff = layers[mask], np.ix_(ss.free, ss.free)
            T, Tinv = energy_coordinates(layer.M[ff], layer.K[ff])
            step[mask] = (T, Tinv, augmented(T @ ss.A @ Tinv, T @ ss.B, ss.omega, dt))
        T, Tinv, E = step[mask]
        same_segment = previous is not None and previous[1] == mask and not (
            ((event_times > previous[0]) & (event_times <= t)).any()) and abs(t - previous[0] - dt) < 1e-9 * dt
        if same_segment:
            reference = E @ reference
            y_ref = Tinv @ reference[:y.size]
            nf = y.size // 2
            errors.append((float(np.abs(y - y_ref)[:nf].max()), float(np.abs(y - y_ref)[nf:].max())))
        else:
            reference = np.concatenate([T @ y, basis(ss.omega, ss.n_harmonics, t)])
        previous = (t, mask)
    assert len(errors) >= 50
    x_scale = max(float(np.abs(row[1][0, :n]).max()) for row in rows)
    v_scale = max(float(np.abs(row[1][1, :n]).max()) for row in rows)
    relative = np.array([max(ex / x_scale, ev / v_scale) for ex, ev in errors])
    # 50 instants spread over the run, and every checked one
    assert relative[np.linspace(0, relative.size - 1, 50).astype(int)].max() < 1e-10
    assert relative.max() < 1e-10


def test_the_state_space_of_1a_is_the_kernels_and_its_particular_solutions_are_exact(run_1a: _ExactRun) -> None:
    layers = run_1a.problem.tables.layers
    for mask, ss in run_1a.spaces.items():
        nf, layer = ss.free.size, layers[mask]
        K, C = layer.K[np.ix_(ss.free, ss.free)], layer.C[np.ix_(ss.free, ss.free)]
        Minv = np.linalg.inv(layer.M[np.ix_(ss.free, ss.free)])
        scale = np.abs(Minv @ K).max()
        assert np.abs(ss.A[nf:, :nf] + Minv @ K).max() < 1e-12 * scale
        assert np.abs(ss.A[nf:, nf:] + Minv @ C).max() < 1e-12 * scale
        # y_p = Y u satisfies y_p' = A y_p + B u: Y S = A Y + B
        for t in np.linspace(0.0, 2 * math.pi / ss.omega, 7):
            rate = ss.Y @ ss.basis_rate(t)
            residual = rate - (ss.A @ ss.particular(t) + ss.forcing(t))
            assert np.abs(residual).max() <= 1e-9 * np.abs(ss.forcing(t)).max()


def small_system(harmonics: int) -> tuple:
    """Two free coordinates on springs and dampers, one prescribed (column 2) with a Fourier series."""
    M = np.diag([2.0, 1.0, 1.0])
    K = np.array([[300.0, -100.0, -200.0], [-100.0, 100.0, 0.0], [-200.0, 0.0, 200.0]])
    C = 0.02 * K + 0.1 * M
    rng = np.random.default_rng(1)
    series = SourceSeries(7.0, (3,), np.array([0.3]), rng.normal(size=(1, harmonics)),
                          rng.normal(size=(1, harmonics)))
    return M, C, K, series


@pytest.mark.parametrize("harmonics", [1, 3, 60])
def test_particular_solution_of_a_fourier_series_satisfies_the_equations(harmonics: int) -> None:
    M, C, K, series = small_system(harmonics)
    ss = state_space(1, np.array([0, 1]), np.array([2]), np.array([0]), M, C, K, series, "I (test)")
    for t in (0.0, 0.1, 0.37, 1.3):
        x_p, v_p, a_p = (np.array([c]) for c in _source(series, t))
        rate = ss.Y @ ss.basis_rate(t)
        y = ss.particular(t)
        # M_FF a + C_FF v + K_FF x = -(M_FP a_P + C_FP v_P + K_FP x_P), directly from the matrices
        left = M[:2, :2] @ rate[2:] + C[:2, :2] @ y[2:] + K[:2, :2] @ y[:2]
        right = -(M[:2, 2:] @ a_p + C[:2, 2:] @ v_p + K[:2, 2:] @ x_p)
        assert np.abs(left - right).max() < 1e-10 * (np.abs(right).max() + np.abs(K[:2, 2:] @ x_p).max())
        assert np.allclose(rate[:2], y[2:], rtol=1e-12, atol=1e-14 * np.abs(y).max())


def _source(series: SourceSeries, t: float) -> tuple[float, float, float]:
    from vtool.solvers.model.sources import evaluate

    x, v, a = evaluate(series, 0, t)
    return float(x), float(v), float(a)


def test_a_constant_load_on_a_rigid_body_mode_names_the_configuration() -> None:
    M = np.eye(3)
    K = np.array([[0.0, 0.0, -50.0], [0.0, 100.0, -100.0], [-50.0, -100.0, 150.0]])  # coordinate 0: no K_FF
    series = SourceSeries(5.0, (3,), np.array([0.2]), np.zeros((1, 1)), np.zeros((1, 1)))
    with pytest.raises(RunError, match=r"configuration III \(seat\) has no steady solution"):
        state_space(4, np.array([0, 1]), np.array([2]), np.array([0]), M, 0.01 * K, K, series, "III (seat)")
    # an unloaded rigid-body mode is allowed (solved on the range of K)
    K[0, 2] = K[2, 0] = 0.0
    ss = state_space(4, np.array([0, 1]), np.array([2]), np.array([0]), M, 0.01 * K, K, series, "III (seat)")
    assert ss.Y[0, 0] == 0.0 and ss.Y[1, 0] == pytest.approx(0.2, rel=1e-14)


def test_peak_brackets_cover_interior_and_end_maxima() -> None:
    values = np.array([[1.0, 3.0, 2.0, 2.5, 4.0], [5.0, 1.0, 0.5, 0.2, 0.1]])
    found = peak_brackets(values, np.array([True, True]), np.array([3.0, 0.0]), margin=0.0)
    assert found == [(0, 0, 2), (0, 3, 4), (1, 0, 1)]
    assert peak_brackets(values, np.array([False, True]), np.array([0.0, 9.0]), margin=0.0) == []


@settings(max_examples=300, deadline=None)
@given(root=st.floats(0.02, 0.98), slope=st.floats(1e-6, 1e6), curve=st.floats(-0.5, 0.5),
       wave=st.floats(0.0, 0.4), frequency=st.floats(0.5, 40.0), tol=st.sampled_from([1e-12, 1e-9, 1e-4]))
def test_safe_newton_finds_the_one_root_to_the_tolerance(
        root: float, slope: float, curve: float, wave: float, frequency: float, tol: float) -> None:
    """f(x) = slope (r - x)(1 + curve (x - r) + wave sin(frequency x)) / 1.5, the second factor positive:
    one root r in (0, 1), positive before it and negative after, with a derivative far from f's secant
    (curvature, ripples, not monotone); the result is within the tolerance of r, whatever the scale."""
    def both(x: float) -> tuple[float, float]:
        shape = 1.0 + curve * (x - root) + wave * math.sin(frequency * x)
        rate = curve + wave * frequency * math.cos(frequency * x)
        return slope * (root - x) * shape / 1.5, slope * (-shape + (root - x) * rate) / 1.5
    assert all(1.0 + curve * (x - root) + wave * math.sin(frequency * x) > 0 for x in np.linspace(0, 1, 101))
    found = safe_newton(both, 0.0, 1.0, both(0.0)[0], both(1.0)[0], tol)
    assert abs(found - root) <= tol


def test_safe_newton_bisects_where_newton_would_not_converge() -> None:
    """Zero and misleading derivatives (a step out of the bracket, or a step not half the last) bisect:
    a cube root's tangent overshoots and a flat plateau has no slope; both still end within the tolerance."""
    def cube(x: float) -> tuple[float, float]:  # f = -cbrt(x - 0.3): Newton alone diverges from any start
        d = x - 0.3
        return -math.copysign(abs(d) ** (1 / 3), d), -(abs(d) ** (-2 / 3)) / 3 if d else -math.inf

    def plateau(x: float) -> tuple[float, float]:  # the secant lands on a flat start (zero slope), root 0.7
        return (1.0, 0.0) if x < 0.6 else (50.0 * (0.7 - x), -50.0)

    for both, root in ((cube, 0.3), (plateau, 0.7)):
        found = safe_newton(both, 0.0, 1.0, both(0.0)[0], both(1.0)[0], 1e-12)
        assert abs(found - root) <= 1e-12, both.__name__


def cam_force(doc: dict, t: np.ndarray) -> np.ndarray:
    """Closed-form cam contact force of the base-excited oscillator (follower on the cam)."""
    mechanism = assemble(spec_from(doc))
    M, K, w, amplitude = mechanism.M, mechanism.K, mechanism.omega, 0.01
    x2, a2 = base_excited_response(mechanism, t, mechanism.start.q[1], mechanism.start.qd[1], amplitude)
    x1, a1 = amplitude * np.sin(w * t) + mechanism.start.cam_offset, -w**2 * amplitude * np.sin(w * t)
    return -(M[0, 0] * a1 + M[0, 1] * a2 + K[0, 0] * x1 + K[0, 1] * x2)


@pytest.mark.parametrize("backend", ["scipy", "exact"])
def test_a_peak_force_between_steps_is_found_to_1e_6(backend: str) -> None:
    doc = base_excited_doc(degrees=360.0)
    mechanism = assemble(spec_from(doc))
    if backend == "scipy":
        trace = ScipyBackend().simulate(mechanism, ScipyOptions(rtol=1e-9))
    else:
        from vtool.solvers.exact.backend import ExactBackend

        trace = ExactBackend().simulate(mechanism)
    assert not trace.events
    # the closed form is the force the back end reports at its outputs (same definition)
    closed = cam_force(doc, trace.time)
    sign = np.sign(closed @ trace.contact_force[:, 0])
    assert np.abs(sign * closed - trace.contact_force[:, 0]).max() < 1e-6 * np.abs(closed).max()
    t = np.linspace(0.0, trace.time[-1], 200001)
    values = sign * cam_force(doc, t)
    i = int(np.argmax(values))
    peak = -scipy.optimize.minimize_scalar(lambda s: -sign * cam_force(doc, np.array([s]))[0],
                                            bounds=(t[max(i - 1, 0)], t[min(i + 1, t.size - 1)]),
                                            method="bounded", options={"xatol": 1e-14}).fun
    assert trace.peak_force[0] == pytest.approx(peak, rel=1e-6)


def test_thread_limit_from_the_environment(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(ENVIRONMENT, raising=False)
    assert thread_limit() == 1
    assert thread_limit("3") == 3 and thread_limit("default") is None and thread_limit("0") is None
    for bad in ("many", "-2", "1.5"):
        with pytest.raises(InputError, match=f"{ENVIRONMENT} = {bad!r}|{ENVIRONMENT}"):
            thread_limit(bad)
    monkeypatch.setenv(ENVIRONMENT, "2")
    assert thread_limit() == 2


def test_limited_caps_the_blas_pools_and_restores_them() -> None:
    pools = [p for p in threadpoolctl.threadpool_info() if p["user_api"] == "blas"]
    if not pools:
        pytest.skip("no BLAS thread pool loaded")
    before = [p["num_threads"] for p in pools]
    with limited(1):
        assert all(p["num_threads"] == 1 for p in threadpoolctl.threadpool_info() if p["user_api"] == "blas")

    @limited(1)
    def inside() -> list[int]:
        return [p["num_threads"] for p in threadpoolctl.threadpool_info() if p["user_api"] == "blas"]

    assert all(n == 1 for n in inside())
    assert [p["num_threads"] for p in threadpoolctl.threadpool_info() if p["user_api"] == "blas"] == before


def test_the_documented_1a_figures_are_regenerated() -> None:
    """docs/valvetrain.md's exact-1a block (benchmarks/bench_exact.py --write): samples, events, peaks."""
    from pathlib import Path

    from vtool.markdown import read_block
    from vtool.solvers.exact.backend import ExactBackend

    block = read_block(Path(__file__).resolve().parent.parent / "docs" / "valvetrain.md", "exact-1a")
    first = [cell.strip() for cell in block.splitlines()[2].strip().strip("|").split("|")]
    trace = ExactBackend().simulate(assemble(load_preset("gnilka-1a")))
    peaks = ", ".join(f"{p:.4f}" for p in trace.peak_force)
    assert first[4:7] == [str(trace.statistics.steps), str(trace.statistics.events), peaks]


@pytest.mark.parametrize("name", ["exact", "scipy"])
def test_piecewise_back_ends_take_the_event_rules_from_transitions(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The piecewise back ends keep no event or impact rules of their own (issue 36): every event of a
    1A run goes through the contact problem's Transitions (one rule, one place), and the run's events
    are the Newmark kernel's rules' (59, the thesis preset's count, docs/valvetrain.md)."""
    from vtool.solvers import backends
    from vtool.solvers.exact import piecewise
    from vtool.solvers.model.contact import Transitions

    assert not hasattr(piecewise.PiecewiseRun, "apply_events") and not hasattr(piecewise.PiecewiseRun, "settle")
    calls = {"start": 0, "apply": 0}
    start, apply = Transitions.start, Transitions.apply

    def counted_start(self: Transitions):  # noqa: ANN202
        calls["start"] += 1
        return start(self)

    def counted_apply(self: Transitions, *args, **kwargs):  # noqa: ANN002, ANN003, ANN202
        calls["apply"] += 1
        return apply(self, *args, **kwargs)

    monkeypatch.setattr(Transitions, "start", counted_start)
    monkeypatch.setattr(Transitions, "apply", counted_apply)
    spec = load_preset("gnilka-1a")
    backend = backends.get(name)()
    trace = backend.simulate(assemble(spec), backend.options_from_run(spec.run))
    assert len(trace.events) == 59
    # one call per event instant (an impact and the release it causes share one)
    assert calls["start"] == 1 and 0 < calls["apply"] <= len(trace.events)
    assert calls["apply"] == len({e.time for e in trace.events if e.time > 0.0})
