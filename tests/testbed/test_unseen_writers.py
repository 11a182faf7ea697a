"""The scenario writers of the rounds of rigs nobody tuned (benchmarks/unseen/roundN/b_make.py,
l_make.py), run on a copy of their round's folder, write its files byte for byte: a round's
files can be regenerated and reviewed from code (rounds 14 and on; the cart-poles of round 14 in
full from cartpole_noise1: an ``extends`` would keep the multisine's keys beside a chirp's)."""

from __future__ import annotations

import contextlib
import runpy
import shutil
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
UNSEEN = ROOT / "benchmarks" / "unseen"


def _sources_only(folder: str, names: list[str]) -> list[str]:
    """``shutil.copytree``'s ``ignore``: all but the folders and the Python sources (the writers
    read no scenario file of a sibling round: copying the 1,700 files took 1.4 s a round)."""
    return [n for n in names if n == "__pycache__"
            or not (n.endswith(".py") or (Path(folder) / n).is_dir())]


@contextlib.contextmanager
def _as_a_script() -> Iterator[None]:
    """Run a writer in this process as ``python <script>`` would (its process was not the
    subject: 1.6 s of CPU for the rounds against 8.3 s in a process each): ``sys.path``,
    ``sys.argv`` and the sibling rounds' modules it imports (``round6.b_make``, ...: each
    writer reads its own copy's) restored afterwards, and its printout swallowed."""
    path, argv = list(sys.path), list(sys.argv)
    drop = [m for m in sys.modules if m.split(".")[0].startswith("round")]
    for m in drop:
        del sys.modules[m]
    try:
        with contextlib.redirect_stdout(None):
            yield
    finally:
        sys.path[:], sys.argv[:] = path, argv
        for m in [m for m in sys.modules if m.split(".")[0].startswith("round")]:
            del sys.modules[m]


@pytest.mark.parametrize("round_name", ["round14", "round15", "round16", "round17", "round18", "round19",
                                        "round20", "round21", "round22", "round23",
                                        "round24", "round25", "round26", "round27", "round28"])
def test_the_writers_reproduce_their_rounds_files(tmp_path, round_name):
    src = UNSEEN / round_name
    work = tmp_path / "unseen"
    shutil.copytree(UNSEEN, work, ignore=_sources_only)  # the writers import their siblings' code
    for script in ("b_make.py", "l_make.py"):
        with _as_a_script():
            runpy.run_path(str(work / round_name / script), run_name="__main__")
    written = sorted(p.name for p in (work / round_name).glob("*.toml"))
    assert written == sorted(p.name for p in src.glob("*.toml"))
    for name in written:
        assert (work / round_name / name).read_bytes() == (src / name).read_bytes(), name
