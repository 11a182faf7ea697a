"""The two tests the identifiers' record rules share (identify._record): the margin of a real
difference and a model mode no measured peak located."""

import numpy as np

from identify._record import AGREEMENT_RATIO, clearly_more, extra_modes


def test_clearly_more_needs_the_margin_and_a_finite_pair():
    assert AGREEMENT_RATIO == 2.0
    assert clearly_more(0.99, 0.97)          # 0.01 left against 0.03: 3 x
    assert not clearly_more(0.75, 0.5)       # exactly 2 x (0.25 against 0.5): no margin (strict)
    assert not clearly_more(0.97, 0.99)
    assert not clearly_more(float("nan"), 0.5) and not clearly_more(0.99, float("nan"))
    assert clearly_more(0.99, 0.98, ratio=1.5)


def test_extra_modes_counts_the_models_modes_among_the_measured_peaks():
    # review 27c: round 24's b24_soft_fs16k at 3 %, s152: peaks 40.0 / 388.4 Hz, the cubic trial's
    # model 39.6 / 373.3 / 425.0 Hz (a spurious mode beside mode 2): three among two peaks
    peaks = np.array([40.0, 388.4])
    assert extra_modes(np.array([39.6, 373.3, 425.0]), peaks)
    assert not extra_modes(np.array([39.6, 390.0, 1100.0]), peaks)   # the third well above
    assert not extra_modes(np.array([39.6, np.nan, 390.0]), peaks)   # no frequency: no mode
    assert not extra_modes(np.array([39.6, 373.3, 425.0]), np.empty(0))
    # review 27f: a real mode no peak located (a heavily damped one between the peaks) is the
    # record's in the model it would replace too: with that baseline, not an extra mode
    assert extra_modes(np.array([40.0, 320.0, 900.0]), np.array([40.0, 900.0]))
    assert not extra_modes(np.array([40.0, 320.0, 900.0]), np.array([40.0, 900.0]),
                           np.array([40.0, 330.0, 905.0]))
    assert extra_modes(np.array([39.6, 373.3, 425.0]), peaks, np.array([39.8, 390.0, 1200.0]))
