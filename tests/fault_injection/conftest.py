"""Fixtures of the fault-injection suite; makes the helper modules beside it importable
(pytest runs in importlib mode).
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

_HERE = str(Path(__file__).resolve().parent)
if _HERE not in sys.path:
    sys.path.insert(0, _HERE)

from easynav.system.testing.system_fixtures import write_params  # noqa: E402


@pytest.fixture
def start_easynav(tmp_path: Path, runtime_factory) -> Callable[[dict[str, Any]], Any]:
    """``start_easynav(document) -> EasyNavRuntime``: writes the params document (strings that
    ROS's YAML parser would read as something else, e.g. ``fault: nan``, are quoted), starts
    an EasyNav in this process and checks it is active. Stopped at the end of the test.
    """
    counter = iter(range(10_000))

    def start(document: dict[str, Any]):
        path = write_params(tmp_path / f"faulty_params_{next(counter)}.yaml", document)
        rt = runtime_factory(path)
        assert rt.start(), rt.error
        return rt

    return start
