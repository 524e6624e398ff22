"""Keep test processes from seeing each other's ROS topics (ENVIRONMENT.md: DDS cross-talk)."""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

FAST_ANNOUNCEMENTS_PROFILE = Path(__file__).with_name("fastdds_fast_announcements.xml")


def isolate_dds(run_id: str | None = None, worker: str | None = None) -> int:
    """Give this process (and the subprocesses it starts) a ROS domain of its own.

    The domain is derived from the test run (``PYTEST_XDIST_TESTRUNUID``, else the pid) and the
    xdist worker (``PYTEST_XDIST_WORKER``), so parallel workers and parallel test runs on one
    machine do not meet; discovery stays on this host. Returns the domain id (1..100).
    """
    run_id = run_id or os.environ.get("PYTEST_XDIST_TESTRUNUID") or str(os.getpid())
    worker = worker or os.environ.get("PYTEST_XDIST_WORKER", "gw0")
    index = int("".join(ch for ch in worker if ch.isdigit()) or 0)
    base = int(hashlib.sha256(run_id.encode()).hexdigest(), 16) % 100
    domain = (base + index) % 100 + 1
    os.environ["ROS_DOMAIN_ID"] = str(domain)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    # Announce participants every 0.2 s: a node that starts after a peer otherwise waits up to
    # the peer's next announcement (~3 s) one time in eight.
    os.environ.setdefault("FASTRTPS_DEFAULT_PROFILES_FILE", str(FAST_ANNOUNCEMENTS_PROFILE))
    return domain
