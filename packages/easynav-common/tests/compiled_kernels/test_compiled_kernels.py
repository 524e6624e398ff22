"""compile_in_child: a kernel's new signatures are compiled by a child process and only loaded
by the caller, so the caller never holds LLVM's compile-time state.

Each case runs in a fresh interpreter with its own empty numba cache (numba reads its cache
directory once, at import), and reports what the caller's dispatcher did: ``misses`` are
signatures the caller compiled itself, ``hits`` ones it loaded from the cache.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("numba")

HERE = Path(__file__).resolve().parent

CALLER = """
import json, logging, sys
import numpy as np
from easynav.common import compiled_kernels
logging.basicConfig(level=logging.WARNING, stream=sys.stdout, format="WARNING %(message)s")
compiled_kernels.enable_child_compilation({enabled})
{patch}
from sample_kernel import weighted_sum
results = [weighted_sum(np.arange(4.0), 2.0), weighted_sum(np.arange(4, dtype=np.float32), 0.5)]
stats = weighted_sum.stats
print(json.dumps({{"results": results, "misses": len(stats.cache_misses),
                  "hits": len(stats.cache_hits), "loaded": len(weighted_sum.overloads)}}))
"""


def run_caller(cache: Path, enabled: bool, patch: str = "") -> tuple[dict, str]:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache),
               PYTHONPATH=os.pathsep.join([str(HERE), os.environ.get("PYTHONPATH", "")]))
    done = subprocess.run([sys.executable, "-c", CALLER.format(enabled=enabled, patch=patch)],
                          env=env, capture_output=True, text=True, timeout=300, cwd=HERE)
    assert done.returncode == 0, done.stderr
    *log, last = done.stdout.strip().splitlines()
    return json.loads(last), "\n".join(log)


def test_enabled_the_caller_compiles_nothing_itself(tmp_path):
    report, log = run_caller(tmp_path, enabled=True)
    assert report["results"] == [12.0, 3.0]
    assert report["misses"] == 0  # both signatures came from a child, through the cache
    assert report["hits"] == 2
    assert report["loaded"] == 2
    assert not log
    assert list(tmp_path.rglob("*.nbc")), "the child wrote numba's cache"


def test_disabled_the_caller_compiles_as_numba_does(tmp_path):
    report, _ = run_caller(tmp_path, enabled=False)
    assert report["results"] == [12.0, 3.0]
    assert report["misses"] == 2


def test_a_warm_cache_starts_no_child(tmp_path):
    run_caller(tmp_path, enabled=True)
    no_child = ("compiled_kernels._compile_in_child = "
                "lambda *a: (_ for _ in ()).throw(AssertionError('a child was started'))")
    report, log = run_caller(tmp_path, enabled=True, patch=no_child)
    assert report["results"] == [12.0, 3.0]
    assert report["misses"] == 0 and report["loaded"] == 2
    assert not log


def test_a_failing_child_falls_back_to_compiling_here_with_a_warning(tmp_path):
    report, log = run_caller(tmp_path, enabled=True,
                             patch="sys.executable = '/nonexistent/python'")
    assert report["results"] == [12.0, 3.0]
    assert report["misses"] == 2
    assert "sample_kernel:weighted_sum" in log and "compiling here" in log


def test_a_kernel_without_a_disk_cache_is_left_as_it_is():
    import numba

    from easynav.common.compiled_kernels import compile_in_child

    dispatcher = numba.njit(lambda x: x + 1)
    hooked = compile_in_child(dispatcher, "nowhere:nothing")
    assert hooked is dispatcher
    assert "_compile_for_args" not in vars(dispatcher)


def test_a_compiled_kernel_is_loaded_once_and_is_none_without_its_module(monkeypatch):
    import numpy as np

    from easynav.common.compiled_kernels import CompiledKernel

    missing = CompiledKernel("easynav_no_such_kernel_module", "kernel")
    assert missing.get() is None and not missing.available()
    monkeypatch.syspath_prepend(str(Path(__file__).parent))
    present = CompiledKernel("sample_kernel", "weighted_sum")
    kernel = present.get()
    assert kernel is present.get() and present.available()
    assert kernel(np.ones(3), 2.0) == 6.0


FROM_A_REALTIME_THREAD = """
import os, sys, threading
import numpy as np
from easynav.common import compiled_kernels
compiled_kernels.enable_child_compilation(True)
from sample_kernel import weighted_sum

def loop_step():
    # What an EasyNav loop is: a SCHED_FIFO thread whose step meets a new kernel signature.
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(70))
    except PermissionError:
        print("no SCHED_FIFO here")
        return
    print(weighted_sum(np.arange(4.0), 2.0))

thread = threading.Thread(target=loop_step)
thread.start()
thread.join()
"""


@pytest.mark.skipif(not hasattr(os, "SCHED_FIFO"), reason="SCHED_FIFO is Linux's")
def test_a_child_started_from_a_realtime_loop_compiles_at_normal_priority(tmp_path):
    """A child started by a SCHED_FIFO loop inherits its policy; compiling for seconds at it
    kept the other processes of its core (a simulator, a test's nodes) from running."""
    policies = tmp_path / "child_policy.txt"
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"),
               EASYNAV_TEST_CHILD_POLICY_FILE=str(policies),
               PYTHONPATH=os.pathsep.join([str(HERE), os.environ.get("PYTHONPATH", "")]))
    done = subprocess.run([sys.executable, "-c", FROM_A_REALTIME_THREAD], env=env,
                          capture_output=True, text=True, timeout=300, cwd=HERE)
    assert done.returncode == 0, done.stderr
    if "no SCHED_FIFO here" in done.stdout:
        pytest.skip("this machine refuses SCHED_FIFO (RLIMIT_RTPRIO 0, no CAP_SYS_NICE)")
    assert done.stdout.split()[-1] == "12.0"
    assert policies.read_text().split() == [str(os.SCHED_OTHER)]


@pytest.mark.skipif(not hasattr(os, "SCHED_FIFO"), reason="SCHED_FIFO is Linux's")
def test_the_child_asks_for_the_normal_policy_before_loading_anything(monkeypatch):
    """The same regression where SCHED_FIFO is refused (the test above skips there): the child
    main lowers an inherited real-time policy before it resolves the kernel."""
    import io
    import pickle

    from easynav.common import compiled_kernels

    calls = []
    monkeypatch.setattr(os, "sched_getscheduler",
                        lambda pid: os.SCHED_FIFO | getattr(os, "SCHED_RESET_ON_FORK", 0))
    monkeypatch.setattr(os, "sched_setscheduler",
                        lambda pid, policy, param: calls.append(("policy", pid, policy)))

    def resolve(locator):
        calls.append(("resolve", locator))
        raise LookupError("stop here")

    monkeypatch.setattr(compiled_kernels, "resolve", resolve)
    payload = io.BytesIO(pickle.dumps(("sample_kernel:weighted_sum", ())))
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(payload))
    with pytest.raises(LookupError):
        compiled_kernels._child_main()
    assert calls == [("policy", 0, os.SCHED_OTHER), ("resolve", "sample_kernel:weighted_sum")]
