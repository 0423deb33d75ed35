"""Figures checked at their definitions: T-pulse forced window, envelope family, `boom daf --json`.

Each check computes its reference in the test itself (closed forms written
out here, or an independently enumerated pulse family), never from our
earlier output.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

from vtool.app.cli.main import cli
from vtool.assessments.sonic_boom.pulses import idealized
from vtool.assessments.sonic_boom.response import peak_response
from vtool.assessments.sonic_boom.spectra import (
    EQUAL_RISE_ENVELOPE,
    THESIS_ENVELOPE,
    envelope,
)


def _n_wave_velocity(u: float, s: float, theta: np.ndarray) -> np.ndarray:
    """Undamped velocity (units p+/(m omega)) under the N-wave ``1 - t/tau`` on [0, s tau].

    Forced: ``v = sin(theta) - (1 - cos(theta))/u``; after the end ``theta_e = u s``
    the motion is free from the end state.
    """
    forced = np.sin(theta) - (1.0 - np.cos(theta)) / u
    te = u * s
    xe = 1.0 - math.cos(te) - (te - math.sin(te)) / u
    ve = math.sin(te) - (1.0 - math.cos(te)) / u
    free = -xe * np.sin(theta - te) + ve * np.cos(theta - te)
    return np.where(theta <= te, forced, free)


@pytest.mark.parametrize("ratio", [0.1, 0.3, 0.5, 0.9, 1.7])
@pytest.mark.parametrize("r2", [0.05, 0.3, 0.8])
def test_t_pulse_with_beta_zero_forced_window_ends_at_s_plus_r2(ratio: float, r2: float) -> None:
    """VELDAF: free motion starts at WST1 = WST + WTR2 whatever beta is.

    T with alpha = 1 and beta = 0 is the N-wave of length s followed by r2 of
    zero pressure, all of it "forced": its forced DAF is the largest |v| of the
    N-wave response over [0, (s + r2) tau], its overall DAF the N-wave's.
    """
    s = 2.0
    pulse = idealized("T", s=s, r1=0.2, r2=r2, alpha=1.0, beta=0.0)
    assert pulse.duration == pytest.approx(s + r2)
    u = 2.0 * math.pi * ratio
    # the grid holds the kink at the N-wave's end shock, where the peak often is
    theta = np.union1d(np.linspace(0.0, u * (s + r2), 400_001), [u * s])
    expected = float(np.max(np.abs(_n_wave_velocity(u, s, theta))))
    res = peak_response(pulse, ratio).velocity
    assert res.forced[0] == pytest.approx(expected, rel=1e-6)
    n_wave = peak_response(idealized("N", s=s), ratio).velocity
    assert res.overall[0] == pytest.approx(n_wave.overall[0], rel=1e-9)


def _members(family: str) -> list:
    """The family enumerated here, independently of EnvelopeSpec.members()."""
    out = []
    for s in (1.6, 1.7, 1.8, 1.9, 2.0, 2.1, 2.2):
        out += [idealized("N", s), idealized("Q", s), idealized("R", s)]
        for r1 in (0.1, 0.2, 0.3, 0.4, 0.5):
            r2 = (s - 1.0) * r1 if family == "thesis" else r1
            out += [idealized("P", s, r1, r2), idealized("T", s, r1)]
    return out


@pytest.mark.parametrize(("spec", "family"), [(THESIS_ENVELOPE, "thesis"),
                                              (EQUAL_RISE_ENVELOPE, "equal-rise")])
def test_envelope_spans_the_stated_family(spec, family: str) -> None:
    ratio = np.linspace(0.02, 2.5, 60)
    members = _members(family)
    expected = np.max([peak_response(p, ratio, quantities=("velocity",)).velocity.overall
                       for p in members], axis=0)
    env = envelope(spec, ratio, "velocity")
    np.testing.assert_allclose(env.daf, expected, rtol=1e-12)
    assert f"({family} family)" in env.statement
    assert f"{len(members)} pulses" in env.statement
    assert ("P r2=(s-1)r1" if family == "thesis" else "P r2=r1") in env.statement


def test_daf_json_parses_and_carries_units(tmp_path) -> None:
    runner = CliRunner()
    result = runner.invoke(cli, ["boom", "daf", "--type", "N", "--range", "0:1:0.1", "--json"])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout)
    assert doc["ratio_unit"].startswith("tau/T") and doc["time_unit"] == "t/tau"
    assert doc["tau_over_T"] == pytest.approx([0.1 * k for k in range(11)])
    v = doc["quantities"]["velocity"]
    assert "daf_unit" in v and len(v["overall"]) == 11
    # the symmetric N-wave's free DAF is 2|sin u/u - cos u|, u = 2 pi tau/T
    u = 2 * math.pi * np.array(doc["tau_over_T"][1:])
    np.testing.assert_allclose(v["free"][1:], 2 * np.abs(np.sin(u) / u - np.cos(u)), rtol=1e-9)
    env = runner.invoke(cli, ["boom", "daf", "--envelope", "--family", "equal-rise",
                              "--range", "0:1:0.25", "--json"])
    assert env.exit_code == 0, env.output
    doc = json.loads(env.stdout)
    assert doc["family"] == "equal-rise" and "(equal-rise family)" in doc["source"]
    assert set(doc["quantities"]) == {"velocity", "displacement"}
