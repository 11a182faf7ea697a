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


def test_a_failing_plugin_module_is_named_and_not_a_silently_partial_registry(tmp_path, monkeypatch):
    """One module of a registry's package that fails to import is an error naming it, on every
    lookup: never a registry that silently lacks that module's entries."""
    import sys

    from testbed.core.registry import PluginError, Registry

    pkg = tmp_path / "brokenpkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("from testbed.core.registry import Registry\n"
                                     "REG = Registry('thing', package='brokenpkg')\n")
    (pkg / "good.py").write_text("from brokenpkg import REG\n@REG.register('good')\nclass Good: pass\n")
    (pkg / "zbad.py").write_text("raise RuntimeError('plugin broke')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        import brokenpkg

        reg: Registry = brokenpkg.REG
        for _ in range(2):  # the second lookup fails the same way, not with a partial registry
            with pytest.raises(PluginError, match=r"brokenpkg\.zbad.*plugin broke"):
                reg.names()
    finally:
        for m in [m for m in sys.modules if m.startswith("brokenpkg")]:
            sys.modules.pop(m)


def test_a_plugin_calling_os_exit_at_import_is_a_plugin_error(tmp_path):
    # os._exit(0) at a plugin's import ended `testbed run` with status 0 and no line (hostile
    # round 20).  In a child: on the old code the call ends the process it is made in.
    import os
    import subprocess
    import sys
    from pathlib import Path

    plugin = tmp_path / "exits.py"
    plugin.write_text("import os\nos._exit(0)\n")
    code = ("from testbed.core.registry import PluginError, import_plugin\n"
            f"try:\n    import_plugin({str(plugin)!r})\n"
            "except PluginError as e:\n    print(e)\n")
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[3])}
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                       timeout=120)
    assert p.returncode == 0 and p.stdout.startswith(
        f"plugin {plugin}: importing it failed: ProcessExitCalled: os._exit(0) called"), (
        p.returncode, p.stdout, p.stderr[-300:])


def test_a_plugins_float_error_state_set_at_import_is_undone(tmp_path):
    # hostile round 20: a plugin's np.seterr(all="raise") at import held for every cell after
    import numpy as np

    from testbed.core.registry import import_plugin

    plugin = tmp_path / "raises.py"
    plugin.write_text("import numpy as np\nnp.seterr(all='raise')\n")
    before = np.geterr()
    try:
        import_plugin(str(plugin))
        assert np.geterr() == before
    finally:
        np.seterr(**before)
