"""A force channel of the wrong sign is found before anything is fitted.

A damper, passive or semi-active, only dissipates: over a test its force does positive net
work on the motion. A load cell read tension-positive against a compression-positive stroke (or
the other way round) gives a recording whose force does net *negative* work; fitted as it is,
every model of the library ends at its bounds (the shared Dyke recording negated: held-out error
0.976 before and after the loop, "unexplained structure" in 91 % of the force). The screening
reports it (``polarity``) and the command-line readers refuse such a file in one line. The real
files' dissipated-work shares are 0.988-1.000 and the virtual laboratory's 0.71-0.995, far from
the -0.2 threshold, so no clean test is flagged.
"""

from __future__ import annotations

import dataclasses

import pytest

from benchmark.applications.cli import main
from benchmark.foundation.errors import InputError
from damper.io.data import read_utfsm, write_csv
from damper.io.dyke import read_dyke
from damper.io.reader import require_samples
from damper.io.screening import POLARITY_SHARE, screen, screened
from damper.lab.laboratory import periodic_test

UTFSM = "hysteresis_data/quiroz_utfsm_mr_damper_sinusoidal/Preprocesados"
DYKE = "hysteresis_data/dyke_mr_damper_random_voltage/ransim_u_converted.csv"


def _polarity(scr):
    return [f for f in scr.findings if f.kind == "polarity"]


def _negated(test, **channels):
    return dataclasses.replace(test, mask=None, metadata={},
                               **{name: -getattr(test, name) for name in channels})


@pytest.mark.parametrize("amplitude, frequency", [(0.02, 1.0), (0.005, 3.0)])
def test_a_negated_force_is_found_and_a_clean_test_is_not(amplitude, frequency):
    test = periodic_test("virtual", amplitude, frequency, 0.5, cycles=6, sample_rate=500.0, noise=0.02, seed=3)
    clean = screen(test)
    assert not _polarity(clean)
    assert clean.estimates["dissipated_work_share"] > 0.5
    flipped = screen(_negated(test, force=True))
    (finding,) = _polarity(flipped)
    assert finding.channel == "force" and not finding.excluded and finding.n_samples == 0
    assert "net negative work" in finding.message and "negate the force column" in finding.message
    assert flipped.estimates["dissipated_work_share"] < -POLARITY_SHARE
    # nothing is excluded for it: the whole test would go, the command line refuses it instead
    assert flipped.usable.all()


def test_a_negated_velocity_channel_is_the_velocity_checks_finding_not_the_forces():
    test = periodic_test("virtual", 0.02, 1.0, 0.5, cycles=6, sample_rate=500.0, noise=0.02, seed=3)
    scr = screen(_negated(test, velocity=True))
    assert not _polarity(scr)
    assert any(f.kind == "velocity" and "times the derivative" in f.message for f in scr.findings)


def test_the_command_line_readers_refuse_a_negated_force_in_one_line():
    test = periodic_test("virtual", 0.02, 1.0, 0.5, cycles=6, sample_rate=500.0, noise=0.01, seed=3)
    require_samples(screened(dataclasses.replace(test, mask=None, metadata={})), "clean.csv")
    with pytest.raises(InputError, match=r"^flipped\.csv: the force does net negative work on the motion") as exc:
        require_samples(screened(_negated(test, force=True)), "flipped.csv")
    assert "\n" not in str(exc.value)


def test_real_recordings_have_the_dampers_sign_and_their_negation_is_found(shared_dir):
    for path in sorted((shared_dir / UTFSM).glob("*.txt")):
        test = read_utfsm(path)
        scr = screen(test)
        assert not _polarity(scr), path.name
        assert scr.estimates["dissipated_work_share"] > 0.9, path.name
        assert _polarity(screen(_negated(test, force=True))), path.name
    dyke = read_dyke(shared_dir / DYKE)
    assert not _polarity(screen(dyke))
    assert _polarity(screen(_negated(dyke, force=True)))


def test_sbib_diagnose_refuses_a_negated_recording(tmp_path, capsys):
    test = periodic_test("virtual", 0.02, 1.0, 0.5, cycles=6, sample_rate=500.0, noise=0.01, seed=3)
    path = write_csv(_negated(test, force=True), tmp_path / "flipped.csv")
    out = tmp_path / "out"
    assert main(["diagnose", "--data", str(path), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("sbib: error:") and "net negative work" in err and "\n" not in err, err
    assert not out.exists()
