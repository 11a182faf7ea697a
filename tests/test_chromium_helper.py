"""The report tests' background Chromium install (tests/_chromium.py): one install per run,
and the fixture waits for it."""

import time

import pytest

from tests import _chromium

pytestmark = pytest.mark.skipif(_chromium.fcntl is None, reason="no flock (Windows)")


def test_one_background_install_and_the_fixture_waits_for_it(tmp_path, monkeypatch):
    marker, runs = tmp_path / "installed", tmp_path / "runs"
    # an "install" of 1 s that counts its runs and leaves a marker, standing for apt-get
    monkeypatch.setattr(_chromium, "INSTALL", f"sleep 1; echo run >> {runs}; touch {marker}")
    monkeypatch.setattr(_chromium, "installable", lambda: True)
    monkeypatch.setattr(_chromium, "find", lambda: str(marker) if marker.exists() else None)
    lock, log = tmp_path / "chromium.lock", tmp_path / "install.log"
    t0 = time.monotonic()
    assert _chromium.start_install(lock, log)
    assert not _chromium.start_install(lock, log)  # the second process starts nothing
    exe, why = _chromium.wait_and_find(lock)
    assert exe == str(marker) and why == ""  # found only once the install had ended ...
    assert runs.read_text().count("run") == 1  # ... the one started, not a second one
    assert time.monotonic() - t0 >= 0.9
    _chromium.wait_started()
    assert not _chromium._started


def test_nothing_started_where_chromium_is_present(tmp_path, monkeypatch):
    monkeypatch.setattr(_chromium, "find", lambda: "/usr/bin/chromium")
    monkeypatch.setattr(_chromium, "installable", lambda: True)
    assert not _chromium.start_install(tmp_path / "l", tmp_path / "log")
    assert _chromium.wait_and_find(tmp_path / "l") == ("/usr/bin/chromium", "")
