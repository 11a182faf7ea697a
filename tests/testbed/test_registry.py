import pytest

from testbed.core.registry import Registry


def test_register_lookup_tags_and_clear_error():
    reg = Registry("widget")

    @reg.register("a", tags=("x", "y"))
    class A:
        pass

    @reg.register("b", tags=("y",))
    class B:
        pass

    assert reg.get("a") is A
    assert reg.names() == ["a", "b"]
    assert reg.names(tag="x") == ["a"]
    assert reg.tags("b") == {"y"}
    with pytest.raises(KeyError, match="unknown widget 'c'; allowed: a, b"):
        reg.get("c")
    with pytest.raises(ValueError, match="registered twice"):
        reg.register("a")(B)


def test_real_registries_load_their_packages():
    from identify import IDENTIFIERS
    from models import RIGS

    assert "cantilever" in RIGS.names()
    assert "fivebar" in RIGS.names()
    assert {"ls_sindy", "sgd_sindy", "sindy_pi"} <= set(IDENTIFIERS.names())
