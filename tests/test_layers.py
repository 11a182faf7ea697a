"""The house in layers (docs/architecture.md): a module imports only its own layer and those
below it, and the rigs and identifiers are reached through one plugin seam, never from inside a
function.  Read from the source with ``ast``, so the test holds for every import, top level or
not."""

import ast
import functools
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

#: Lowest first.  ``models`` and ``identify`` share a floor but never import each other.
LAYERS = ["testbed.core", "testbed.numerics", "models|identify", "testbed.pipeline",
          "testbed.scoring", "testbed.studies", "testbed.reporting", "testbed.cli|testbed.server"]


def layer_of(module: str) -> int | None:
    """Floor of a project module name, None for outside packages (numpy, mujoco, ...)."""
    top = module.split(".")[0]
    if top in ("models", "identify"):
        return 2
    if top != "testbed":
        return None
    for i, names in enumerate(LAYERS):
        if any(module == name or module.startswith(name + ".") for name in names.split("|")):
            return i
    return -1  # testbed/__init__.py and testbed.plugins-free top-level names: checked below


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


@functools.cache  # each source is read by up to three of the tests below: parsed once a process
def imports(path: Path) -> tuple[tuple[str, bool], ...]:
    """(imported module, inside a function?) for every import statement of the file."""
    tree = ast.parse(path.read_text())
    out = []

    def visit(node, in_fn):
        for child in ast.iter_child_nodes(node):
            fn = in_fn or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef))
            if isinstance(child, ast.Import):
                out.extend((a.name, fn) for a in child.names)
            elif isinstance(child, ast.ImportFrom) and child.level == 0 and child.module:
                out.append((child.module, fn))
                out.extend((f"{child.module}.{a.name}", fn) for a in child.names)
            elif isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
                continue  # annotations only
            visit(child, fn)

    visit(tree, False)
    return tuple(out)


SOURCES = sorted(p for pkg in ("testbed", "models", "identify") for p in (ROOT / pkg).rglob("*.py"))


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(ROOT)))
def test_imports_point_down(path):
    me = module_name(path)
    mine = layer_of(me)
    if mine == -1:  # the package root re-exports the public API from every layer
        return
    for target, _ in imports(path):
        theirs = layer_of(target)
        if theirs is None or theirs == -1:
            continue
        assert theirs <= mine, f"{me} (floor {LAYERS[mine]}) imports {target} (floor {LAYERS[theirs]})"
        if mine == 2:
            assert target.split(".")[0] == me.split(".")[0] or theirs < 2, \
                f"{me} imports {target}: rigs and identifiers never import each other"


@pytest.mark.parametrize("path", sorted((ROOT / "testbed").rglob("*.py")),
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_rigs_and_identifiers_only_through_the_plugin_seam(path):
    me = module_name(path)
    for target, in_fn in imports(path):
        if target.split(".")[0] in ("models", "identify"):
            assert me == "testbed.pipeline.plugins", f"{me} imports {target}; use testbed.pipeline.plugins"
            assert not in_fn, f"{me} imports {target} inside a function"


@pytest.mark.parametrize("path", sorted((ROOT / "testbed").rglob("*.py")),
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_no_project_import_hides_in_a_function(path):
    """Project modules are imported at module top, so the arrows above are the whole story.
    Only the CLI imports lazily (a command pays for what it uses: start-up time); optional
    heavy third-party packages (pyuff, distributed, rich) may be imported where used."""
    if path.name in ("cli.py", "server.py"):  # the command line and its resident server
        return
    project = ("testbed", "models", "identify")
    hidden = [t for t, in_fn in imports(path) if in_fn and t.split(".")[0] in project]
    assert not hidden, f"{module_name(path)} imports {hidden} inside a function"


@pytest.mark.parametrize("path", sorted((ROOT / "identify").rglob("*.py")),
                         ids=lambda p: str(p.relative_to(ROOT)))
def test_identifiers_cannot_reach_the_truth(path):
    """An identifier sees what a lab would measure (a Measurement), never the truth: no module of
    ``identify`` imports the typed truth or the Dataset that carries it (docs/architecture.md,
    Boundaries), not even from core, the floor below it."""
    truth_modules = ("testbed.core.truth", "testbed.core.dataset")
    reached = [t for t, _ in imports(path)
               if any(t == m or t.startswith(m + ".") for m in truth_modules)]
    assert not reached, f"{module_name(path)} imports {reached}"


def test_tests_mirror_the_packages():
    """``tests/testbed/<layer>/`` holds the tests of ``testbed/<layer>/`` (tests/testbed itself:
    the CLI, the server and the cross-cutting audits); ``tests/identify`` and ``tests/models``
    mirror theirs."""
    tests = ROOT / "tests" / "testbed"
    folders = {p.name for p in tests.iterdir() if p.is_dir() and p.name != "__pycache__"}
    packages = {p.name for p in (ROOT / "testbed").iterdir() if (p / "__init__.py").is_file()}
    assert folders <= packages, f"tests/testbed folders without a package: {folders - packages}"
    assert {"core", "numerics", "pipeline", "scoring", "studies", "reporting"} <= folders
    for layer in folders:
        for f in sorted((tests / layer).glob("test_*.py")):
            targets = [t for t, _ in imports(f)]
            assert any(t == f"testbed.{layer}" or t.startswith(f"testbed.{layer}.")
                       for t in targets), f"{f.relative_to(ROOT)} tests nothing of testbed.{layer}"
