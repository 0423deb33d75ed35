"""Event pairing between two runs, and the accuracy study's bookkeeping."""

from __future__ import annotations

from dataclasses import replace

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vtool.solvers.studies.pairing import pair_events
from vtool.solvers.trace import Event

PERIOD = 60.0 / 11000.0  # s per cam revolution at 11,000 rev/min


def event(time: float, clearance: str, kind: str) -> Event:
    return Event(time, time / PERIOD * 360.0, clearance, kind, -1.0, 0, 0)


def reference_sequence(cycles: int = 3) -> list[Event]:
    """Per revolution: a seat impact with one bounce, a lash opening, a cam impact, a rocker ping."""
    events = []
    for n in range(cycles):
        t0 = n * PERIOD
        for fraction, clearance, kind in ((0.10, "seat", "closed"), (0.11, "seat", "opened"),
                                          (0.12, "seat", "closed"), (0.15, "cam", "opened"),
                                          (0.40, "cam", "closed"), (0.45, "rocker", "opened"),
                                          (0.46, "rocker", "closed")):
            events.append(event(t0 + fraction * PERIOD, clearance, kind))
    return events


def test_identical_runs_pair_every_event() -> None:
    ref = reference_sequence()
    pairing = pair_events(ref, list(ref))
    assert pairing.pairs == tuple((i, i) for i in range(len(ref)))
    assert pairing.unmatched == 0


def test_one_inserted_and_one_deleted_event_are_the_only_unmatched_ones() -> None:
    """Every other event keeps its partner, 1 µs away, never one a cycle away."""
    ref = reference_sequence()
    shifted = [replace(e, time=e.time + 1e-6, cam_angle=e.cam_angle + 1e-6 / PERIOD * 360.0) for e in ref]
    deleted = 9  # the second cycle's seat bounce (opened)
    inserted = event(ref[4].time + 0.05 * PERIOD, "cam", "opened")  # a spurious separation after the cam impact
    other = shifted[:deleted] + shifted[deleted + 1:]
    other.insert(5, inserted)
    pairing = pair_events(ref, other)
    assert pairing.missing == (deleted,)
    assert [other[j] for j in pairing.extra] == [inserted]
    assert pairing.unmatched == 2
    assert len(pairing.pairs) == len(ref) - 1
    for i, j in pairing.pairs:
        assert (ref[i].clearance, ref[i].kind) == (other[j].clearance, other[j].kind)
        assert abs(ref[i].cam_angle - other[j].cam_angle) < 0.1  # 1 µs; never a cycle (360 deg) apart


def test_an_event_beyond_half_the_spacing_is_unmatched() -> None:
    ref = [event(0.0, "cam", "closed"), event(1.0, "cam", "closed"), event(2.0, "cam", "closed")]
    late = [event(0.0, "cam", "closed"), event(1.6, "cam", "closed"), event(2.0, "cam", "closed")]
    pairing = pair_events(ref, late)
    assert pairing.pairs == ((0, 0), (2, 2))
    assert pairing.missing == (1,) and pairing.extra == (1,)


def test_a_different_kind_or_clearance_is_never_a_partner() -> None:
    ref = [event(1.0, "cam", "closed")]
    pairing = pair_events(ref, [event(1.0, "cam", "opened"), event(1.0, "seat", "closed")])
    assert pairing.pairs == () and pairing.unmatched == 3


def test_the_nearest_of_several_candidates_is_the_partner() -> None:
    ref = [event(0.0, "cam", "closed"), event(1.0, "cam", "closed")]
    other = [event(0.0, "cam", "closed"), event(0.8, "cam", "closed"), event(1.1, "cam", "closed")]
    pairing = pair_events(ref, other)
    assert pairing.pairs == ((0, 0), (1, 2)) and pairing.extra == (1,)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(0.0, 1.0), st.sampled_from(["cam", "seat"]),
                          st.sampled_from(["opened", "closed"])), max_size=30),
       st.lists(st.tuples(st.floats(0.0, 1.0), st.sampled_from(["cam", "seat"]),
                          st.sampled_from(["opened", "closed"])), max_size=30))
def test_pairing_invariants(ref_items: list, other_items: list) -> None:
    """Every event is in exactly one pair or unmatched; partners share clearance and kind."""
    ref = [event(t, c, k) for t, c, k in sorted(ref_items)]
    other = [event(t, c, k) for t, c, k in sorted(other_items)]
    pairing = pair_events(ref, other)
    refs = [i for i, _ in pairing.pairs] + list(pairing.missing)
    others = [j for _, j in pairing.pairs] + list(pairing.extra)
    assert sorted(refs) == list(range(len(ref)))
    assert sorted(others) == list(range(len(other)))
    for i, j in pairing.pairs:
        assert (ref[i].clearance, ref[i].kind) == (other[j].clearance, other[j].kind)
    assert pair_events(ref, ref).unmatched == 0


@pytest.mark.parametrize("module", ["vtool.solvers.studies.accuracy", "vtool.solvers.studies.pairing"])
def test_solvers_do_not_import_presets(module: str) -> None:
    import subprocess
    import sys

    code = f"import sys, {module}\nprint(any(m.startswith('vtool.presets') for m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_a_burst_shifted_as_a_whole_keeps_its_order_within_the_resolution() -> None:
    """Contacts 2 µs apart, all placed 3 µs late: beyond half their spacing, within the resolution."""
    ref = [event(t, "rocker", "closed") for t in (0.0, 2e-6, 4e-6, 1.0)]
    late = [event(t + 3e-6, "rocker", "closed") for t in (0.0, 2e-6, 4e-6)] + [event(1.0, "rocker", "closed")]
    assert pair_events(ref, late).unmatched == 4
    pairing = pair_events(ref, late, resolution=1e-5)
    assert pairing.pairs == ((0, 0), (1, 1), (2, 2), (3, 3))


def test_cli_prints_the_table_and_writes_csv(tmp_path) -> None:  # noqa: ANN001
    from click.testing import CliRunner

    from vtool.app.cli.main import cli

    out = tmp_path / "acc.csv"
    result = CliRunner().invoke(cli, ["accuracy", "gnilka-1d", "--degrees", "30", "--csv", str(out)])
    assert result.exit_code == 0, result.output
    assert "unmatched" in result.output and "refused" in result.output
    lines = out.read_text().splitlines()
    assert lines[0].startswith("backend,setting,wall time (s),steps,events,unmatched")
    assert len(lines) == 1 + 1 + 14 + 1 + 6  # header, exact, Newmark 7 steps x 2 betas, plain, scipy 6 rtols


def test_cli_refuses_a_non_valvetrain_preset() -> None:
    from click.testing import CliRunner

    from vtool.app.cli.main import cli

    result = CliRunner().invoke(cli, ["accuracy", "plate-table2"])
    assert result.exit_code == 2
    # the shared wrong-kind check (presets/kinds.py require_kind): one house line, as `vtool modes`
    assert result.output.strip().splitlines() == [
        "error: preset: got 'plate', expected a valvetrain preset for `vtool accuracy`"]


def test_a_wrong_late_peak_is_not_hidden_by_the_start_shock_and_a_pull_is_noted() -> None:
    """The whole-run peaks of gnilka-1a are its start shock; a run whose peaks after the first revolution are
    3.77 times the reference's (scipy's +277 % on 1D at rtol 1e-6) must show a 277 % peak-force error, and one
    whose closed rocker pulled must say so."""
    import numpy as np

    from tests.valvetrain_cases import spec_from, thesis_doc
    from vtool.solvers.run import simulate
    from vtool.solvers.studies.accuracy import compare

    doc = thesis_doc("gnilka-1a")
    doc["run"]["degrees"] = 400.0
    reference = simulate(spec_from(doc))
    late = reference.peak_force_after_first_revolution
    assert late is not None and np.all(late < reference.peak_force)  # the start shock is the run's peak
    wrong = replace(reference, peak_force_after_first_revolution=3.77 * late)
    assert compare(wrong, reference, "scipy", "test").peak_force_error == pytest.approx(2.77, rel=1e-9)
    forces = reference.contact_force.copy()
    row = int(np.argmax(forces[:, 1] > 0))  # a row where the rocker is closed
    forces[row, 1] = -1000.0
    pulled = compare(replace(reference, contact_force=forces), reference, "scipy", "test", "scipy 1.17.1")
    assert pulled.note == "closed contacts pulled: F2 -1e+03 lbf; scipy 1.17.1"
    assert compare(reference, reference, "newmark", "test").note == ""
