"""testbed.numerics.gram on a case worked by hand: column 2 = column 0 + column 1."""

import numpy as np

from testbed.numerics.gram import normalized_gram, ordered_independent


def test_dependent_column_found_in_priority_order():
    rng = np.random.default_rng(0)
    a, b = rng.standard_normal(50), rng.standard_normal(50)
    X = np.c_[a, 3.0 * b, a + 3.0 * b, rng.standard_normal(50)]
    Gn, s = normalized_gram(X.T @ X)
    assert np.allclose(np.diag(Gn), 1.0) and np.allclose(s, np.linalg.norm(X, axis=0))
    kept, dep, res = ordered_independent(Gn, np.arange(4), 1e-10)
    # column 2 is exactly a + 3 b: its residual is rounding only
    assert kept == [0, 1, 3] and dep == [2] and res[0] < 1e-12
    kept, dep, _ = ordered_independent(Gn, np.array([2, 1, 0, 3]), 1e-10)
    assert kept == [2, 1, 3] and dep == [0]  # priority decides which of the three goes
