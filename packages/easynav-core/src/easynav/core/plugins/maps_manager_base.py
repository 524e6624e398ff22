"""MapsManagerBase: plugins that own an environment representation."""

from __future__ import annotations

from easynav.core.nav_state import NavState
from easynav.core.plugins.method_base import MethodBase


class MapsManagerBase(MethodBase):
    """A maps manager: ``update`` (non-RT, at ``freq``) writes its map keys, conventionally
    ``map.base`` (the static map) and ``map`` (with live obstacles).
    """

    HAS_UPDATE = True

    def update(self, nav_state: NavState) -> None:
        """Update the maps. Non-RT thread."""
        raise NotImplementedError
