"""ROS domains of test processes and runs: a domain held by one is never handed to another.

A CI run failed on this: a matrix test ran the demo on a domain of its own and, in doing so,
released the domain its worker's other tests used; another worker's demo then took that domain
and its robot, clock and TF reached a scenario test of the first worker.
"""

from __future__ import annotations

import pytest

from easynav.system.testing import dds_isolation
from easynav.system.testing.dds_isolation import DomainReservation, reserve_domain


@pytest.fixture
def lock_dir(tmp_path, monkeypatch):
    """Locks in a directory of the test, so the suite's own processes are not in the way."""
    monkeypatch.setattr(dds_isolation, "LOCK_DIR", tmp_path)
    monkeypatch.setattr(dds_isolation, "_held_locks", [])
    yield tmp_path
    for reservation in dds_isolation._held_locks:
        reservation.release()


def _free(domain: int) -> bool:
    handle = dds_isolation._try_lock(domain)
    if handle is None:
        return False
    handle.close()
    return True


def test_a_process_keeps_every_domain_it_reserved_for_its_lifetime(lock_dir):
    first = reserve_domain("worker")
    second = reserve_domain("worker")  # e.g. a demo run by one of its tests
    assert first != second
    assert not _free(first) and not _free(second)


def test_a_run_reservation_never_takes_a_held_domain_and_gives_its_own_back(lock_dir):
    held = reserve_domain("same seed")
    with DomainReservation.acquire("same seed") as run:
        assert run.domain != held
        assert not _free(run.domain)
    assert _free(run.domain)
    assert not _free(held)  # the process's own domain stays held after the run


def test_when_every_domain_is_held_the_error_names_the_lock_directory(lock_dir, monkeypatch):
    monkeypatch.setattr(dds_isolation, "DOMAIN_COUNT", 2)
    reserve_domain("a")
    reserve_domain("b")
    with pytest.raises(RuntimeError, match=str(lock_dir)):
        DomainReservation.acquire("c")
