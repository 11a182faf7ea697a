"""The two linear-model reasons ("linear model" for the frequencies, for the TRAC): an unpaired
mode's MAC bar is exempted only where the frequency reason names that mode (28a L1), and each
reason is computed once per :func:`bar_failures` (28a L9)."""

import numpy as np

from testbed.scoring import scorers
from testbed.scoring.scorers import Scores, bar_failures, hidden_by_frequency, hidden_by_trac

NAN = float("nan")
#: review 26d's unpaired-mode record (the truth's cubic force 0.531 x its linear one; mode 1's
#: reach 0.27): mode 1 3 % off within its reach, true mode 2 with no partner (NaN MAC and
#: frequency error)
DETAILS = {"truth_cubic_share": 0.531, "truth_cubic_reach": np.array([0.27, 0.033]),
           "mac_per_mode": np.array([0.99, NAN]), "freq_error_per_mode": np.array([0.03, NAN])}
VALUES = {"K3_norm": 0.0, "freq_error_mode1": 0.03, "freq_error_mode2": NAN, "mac_mode1": 0.99,
          "mac_mode2": NAN, "freq_error": NAN, "mac": NAN}


def test_an_unpaired_modes_mac_is_exempted_only_where_the_frequency_reason_names_it():
    s = Scores(dict(VALUES), dict(DETAILS))
    # mode 2's frequency bar held too: the reason names mode 2 "no partner", so its MAC hides
    # nothing (review 26d's case, kept)
    named = {"freq_error_mode1": {"max": 0.026}, "freq_error_mode2": {"max": 0.026},
             "mac_mode2": {"min": 0.9}}
    why = bar_failures(s, named)
    assert set(why) == {"cubic"} and "mode 2 has no partner" in why["cubic"]
    assert hidden_by_frequency(s, named) == []
    # no frequency bar on mode 2: the reason speaks of mode 1 alone and never names mode 2, so
    # mode 2's failed MAC is one it would hide (the old exemption took the NaN pair as named
    # and gave "linear model" for the whole cell)
    unnamed = {"freq_error_mode1": {"max": 0.026}, "mac_mode2": {"min": 0.9}}
    assert [c.metric for c in hidden_by_frequency(s, unnamed)] == ["mac_mode2"]
    assert bar_failures(s, unnamed) == {}
    # the worst-over-modes MAC bar: exempted where the reason names every unpaired mode ...
    worst = {"freq_error": {"max": 0.026}, "mac": {"min": 0.9}}
    assert set(bar_failures(s, worst)) == {"cubic"}
    # ... and not beside a frequency bar on mode 1 alone (mode 2 unnamed)
    assert bar_failures(s, {"freq_error_mode1": {"max": 0.026}, "mac": {"min": 0.9}}) == {}
    # no per-mode MAC known: which mode is unpaired is unknown, so nothing is exempted
    bare = Scores(dict(VALUES), {k: v for k, v in DETAILS.items() if k != "mac_per_mode"})
    assert bar_failures(bare, worst) == {}
    # a TRAC reason is vetoed the same way (the other judge, the same exemption): nothing
    # hidden where mode 2 is named, mode 2's MAC left where it is not
    assert hidden_by_trac(s, {**named, "trac": {"min": 0.9}}) == []
    assert "mac_mode2" in [c.metric for c in hidden_by_trac(s, {**unnamed, "trac": {"min": 0.9}})]


def test_each_linear_reason_is_computed_once_per_bar_failures(monkeypatch):
    calls = {"claim": 0, "trac": 0}
    claim, trac = scorers._linear_model_claim, scorers._linear_trac_reason

    def counted_claim(*a):
        calls["claim"] += 1
        return claim(*a)

    def counted_trac(*a):
        calls["trac"] += 1
        return trac(*a)

    monkeypatch.setattr(scorers, "_linear_model_claim", counted_claim)
    monkeypatch.setattr(scorers, "_linear_trac_reason", counted_trac)
    bars = {"freq_error_mode1": {"max": 0.026}, "freq_error_mode2": {"max": 0.026},
            "trac": {"min": 0.9}}
    details = {**DETAILS, "trac": np.array([0.95, 0.85]), "truth_linear_trac": np.array([0.9, 0.6]),
               "channels": ["acc1", "acc2"]}
    why = bar_failures(Scores({**VALUES, "trac": 0.85}, details), bars)
    assert set(why) == {"cubic", "cubic_trac"}  # both given, each judged against the other
    assert calls == {"claim": 1, "trac": 1}  # was 2 and 2


def test_the_worst_mac_bar_is_exempted_only_where_every_paired_mode_meets_it():
    """Review 29b M2: a paired mode's failed MAC (0.30) under the worst-over-modes bar, whose
    value the unpaired mode 3 makes NaN, was hidden and the cell given "cubic"."""
    details = dict(DETAILS, mac_per_mode=np.array([0.99, 0.30, NAN]),
                   freq_error_per_mode=np.array([0.03, 0.01, NAN]),
                   truth_cubic_reach=np.array([0.27, 0.05, 0.03]))
    values = dict(VALUES, freq_error_mode2=0.01, mac_mode2=0.30, freq_error_mode3=NAN,
                  mac_mode3=NAN)
    s = Scores(values, details)
    worst = {"freq_error": {"max": 0.026}, "mac": {"min": 0.9}}
    assert [c.metric for c in hidden_by_frequency(s, worst)] == ["mac"]
    assert bar_failures(s, worst) == {}


def test_an_unpaired_mode_another_reason_names_does_not_withhold_the_cubic_reason():
    """Review 29b M1: true mode 2 unpaired and above the low-pass (the band reason names it);
    the worst-over-modes MAC bar is then explained, so mode 1's 3 % keeps its cubic reason."""
    details = dict(DETAILS, passband=(1.0, 100.0), f_true=np.array([20.0, 400.0]))
    s = Scores(dict(VALUES), details)
    worst = {"freq_error": {"max": 0.026}, "mac": {"min": 0.9}}
    assert hidden_by_frequency(s, worst) == []
    assert set(bar_failures(s, worst)) == {"band", "cubic"}
