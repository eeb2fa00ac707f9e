"""The verdict 'nothing left' says when the held-out residual is not white: a probe's recording with
its force channel 10 ms late ended at 0.31 held-out error with 'no unexplained structure left'
while the residual's lag-1 autocorrelation was 0.997 (no trace variable sees a skew)."""

from __future__ import annotations

from types import SimpleNamespace

from damper.diagnosis.report import residual_not_white


def _diagnosis(unexplained: bool, noise_fraction: float):
    return SimpleNamespace(unexplained=unexplained,
                           trace_after=SimpleNamespace(noise_fraction=noise_fraction, lag1=0.995))


def test_a_structured_residual_nothing_explains_is_said():
    text = residual_not_white(_diagnosis(False, 0.005))
    assert "not white" in text and "0.005" in text and "0.995" in text


def test_a_white_residual_or_an_unexplained_verdict_adds_nothing():
    assert residual_not_white(_diagnosis(False, 0.8)) == ""
    assert residual_not_white(_diagnosis(True, 0.005)) == ""
