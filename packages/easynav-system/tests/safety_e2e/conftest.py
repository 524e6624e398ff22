"""Fixtures of the end-to-end safety suite; makes the helper modules beside it importable
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
def write_document(tmp_path: Path) -> Callable[[dict[str, Any]], str]:
    """``write_document(document) -> path`` of a params file ROS reads with the same types."""
    counter = iter(range(10_000))

    def write(document: dict[str, Any]) -> str:
        return write_params(tmp_path / f"safety_params_{next(counter)}.yaml", document)

    return write


@pytest.fixture
def start_easynav(write_document, runtime_factory) -> Callable[..., Any]:
    """``start_easynav(document, namespace="") -> EasyNavRuntime``: an EasyNav in this process,
    checked active (stopped at the end of the test).
    """

    def start(document: dict[str, Any], namespace: str = ""):
        rt = runtime_factory(write_document(document), namespace)
        assert rt.start(), rt.error
        return rt

    return start
