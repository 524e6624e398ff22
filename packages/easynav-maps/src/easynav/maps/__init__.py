"""EasyNav maps managers: the simple binary grid (SimpleMap, SimpleMapsManager)."""
