import pytest

from testbed.core.terms import canonical


@pytest.mark.parametrize(("raw", "name", "sign"), [
    ("ddth2*sin(th3-th2)", "sin(th2-th3)*ddth2", -1),
    ("cos(th2-th1)*ddth2", "cos(th1-th2)*ddth2", 1),
    ("dth2*sin(th1-th2)*dth2", "sin(th1-th2)*dth2^2", 1),
    ("u1*sin(th2-th3)", "sin(th2-th3)*u1", 1),
    ("sin(th2-th1)*sin(th3-th2)*ddth1", "sin(th1-th2)*sin(th2-th3)*ddth1", 1),
    ("1", "1", 1),
])
def test_canonical_names(raw, name, sign):
    assert canonical(raw) == (name, sign)
    # canonical names are fixed points
    assert canonical(name) == (name, 1)
