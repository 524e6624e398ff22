"""Keep test processes from seeing each other's ROS topics (DDS cross-talk between processes).

Fast DDS participants on one machine discover each other whenever they share a ROS domain, so
two test processes that run at once must never share one: a test that listens on ``cmd_vel``
would otherwise hear another test's robot. A domain derived from a hash is not enough (two of
the eight concurrent runs a busy machine sees would share one of 100 domains one time in
eight): each process reserves its domain with an exclusive lock on a file and keeps it until it
exits, so the lock is released even when the process is killed.
"""

from __future__ import annotations

import fcntl
import hashlib
import os
import tempfile
from pathlib import Path

FAST_ANNOUNCEMENTS_PROFILE = Path(__file__).with_name("fastdds_fast_announcements.xml")

#: Domains handed to test processes: 1..101 (ROS 2 recommends 0..101 on Linux, where higher
#: domains can collide with the ephemeral port range; 0 is left to people's own ROS graphs).
FIRST_DOMAIN = 1
DOMAIN_COUNT = 101
LOCK_DIR = Path(tempfile.gettempdir()) / "easynav-ros-domains"

# The open lock files of the domains this process holds for its lifetime: they must stay open.
_held_locks: list = []


def _try_lock(domain: int):
    LOCK_DIR.mkdir(parents=True, exist_ok=True)
    handle = open(LOCK_DIR / f"domain-{domain}.lock", "a+")  # noqa: SIM115 (held until released)
    try:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        handle.close()
        return None
    return handle


class DomainReservation:
    """A ROS domain held by this process until :meth:`release` (or the end of a ``with``).

    Thread contract: one owner thread. Raises RuntimeError (from :meth:`acquire`) when every
    domain is held by another reservation.
    """

    def __init__(self, domain: int, handle) -> None:
        self.domain = domain
        self._handle = handle

    @classmethod
    def acquire(cls, seed: str) -> DomainReservation:
        """Reserve a domain no other reservation of this machine holds.

        The search starts at a domain derived from ``seed`` (so concurrent runs spread out) and
        takes the first free one.
        """
        start = int(hashlib.sha256(seed.encode()).hexdigest(), 16) % DOMAIN_COUNT
        for offset in range(DOMAIN_COUNT):
            domain = FIRST_DOMAIN + (start + offset) % DOMAIN_COUNT
            handle = _try_lock(domain)
            if handle is not None:
                return cls(domain, handle)
        raise RuntimeError(
            f"every ROS domain {FIRST_DOMAIN}..{FIRST_DOMAIN + DOMAIN_COUNT - 1} is held by "
            f"another process or run (locks in {LOCK_DIR})"
        )

    def release(self) -> None:
        """Give the domain back (its processes must have stopped: the next holder shares it)."""
        if self._handle is not None:
            self._handle.close()
            self._handle = None

    def __enter__(self) -> DomainReservation:
        return self

    def __exit__(self, *exc) -> None:
        self.release()


def reserve_domain(seed: str) -> int:
    """Reserve a ROS domain no other living process of this machine holds, for the rest of this
    process's life; return it.

    Every domain reserved this way stays held: a test process that also runs a demo on a domain
    of its own must keep the domain its other tests use (another process taking it would hear
    them). A run that ends before the process does uses :class:`DomainReservation` instead.
    Raises RuntimeError when all are taken.
    """
    reservation = DomainReservation.acquire(seed)
    _held_locks.append(reservation)
    return reservation.domain


def isolate_dds(run_id: str | None = None, worker: str | None = None) -> int:
    """Give this process (and the subprocesses it starts) a ROS domain of its own.

    Each test process (every xdist worker, the xdist controller, a plain pytest) reserves a
    domain that no other living process holds; the subprocesses it starts inherit it through
    ``ROS_DOMAIN_ID``. Discovery stays on this host. Returns the domain id.
    """
    run_id = run_id or os.environ.get("PYTEST_XDIST_TESTRUNUID") or str(os.getpid())
    worker = worker or os.environ.get("PYTEST_XDIST_WORKER", "gw0")
    domain = reserve_domain(f"{run_id}/{worker}/{os.getpid()}")
    os.environ["ROS_DOMAIN_ID"] = str(domain)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    # Announce participants every 0.2 s: a node that starts after a peer otherwise waits up to
    # the peer's next announcement (~3 s) one time in eight.
    os.environ.setdefault("FASTRTPS_DEFAULT_PROFILES_FILE", str(FAST_ANNOUNCEMENTS_PROFILE))
    return domain
