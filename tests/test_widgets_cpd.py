"""The curvature explorer's title: the channel verdict and the estimate verdict are separate."""

import numpy as np

from tunnelkit.widgets.cpd import _verdicts


def _st(kappa, mismatch=0.05):
    return {
        "kappa": np.asarray(kappa, float),
        "kappa_vue": 29.7,
        "kappa_reflection": 21.5,
        "mismatch": mismatch,
    }


def test_scattered_estimates_resolve_neither_even_when_the_channel_is_srnf():
    v = _verdicts(_st([7.0, 26.0, 12.0, 18.0]))
    assert v.startswith("channel SR-NF within eps_Phi")
    assert "7.0-26.0 m resolves neither" in v


def test_tight_estimates_name_the_candidate_they_sit_on():
    assert _verdicts(_st([29.5, 29.8, 29.6], mismatch=0.3)).endswith(": VUE")
    assert "M > Mmax" in _verdicts(_st([29.5, 29.8], mismatch=0.3))
    assert _verdicts(_st([21.4, 21.6])).endswith(": reflection point")
    assert _verdicts(_st([40.0, 40.1])).endswith(": neither")


def test_no_positive_curvature_is_the_far_field_fallback():
    assert _verdicts(_st([-1.0, np.nan])).endswith("far-field fallback)")
