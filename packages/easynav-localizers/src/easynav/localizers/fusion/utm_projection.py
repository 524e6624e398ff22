"""UtmProjection: latitude/longitude to local east/north metres (UTM, fixed zone), via pyproj."""

from __future__ import annotations


class UtmProjection:
    """A local metric frame on the UTM zone of a geodetic origin (WGS 84).

    :meth:`forward` gives ``(east, north)`` metres of a fix relative to the origin's UTM
    coordinates, in the origin's zone even when the fix lies in the next one (the original's
    fixed zone: no jump at a zone border); :meth:`inverse` goes back. The zone (including the
    Norway/Svalbard exceptions) comes from the EPSG database through pyproj.

    Raises ImportError naming the extra when pyproj is missing, ValueError for a non-finite or
    out-of-range origin. Thread contract: immutable after construction (pyproj transformers are
    used from the owner's thread only).
    """

    def __init__(self, latitude: float, longitude: float, altitude: float = 0.0) -> None:
        try:
            from pyproj import CRS, Transformer
            from pyproj.aoi import AreaOfInterest
            from pyproj.database import query_utm_crs_info
        except ImportError as exc:  # an optional extra
            raise ImportError(
                "GNSS localisation needs pyproj: pip install easynav-localizers[fusion] "
                "(or [gps])"
            ) from exc
        if not (-90.0 <= latitude <= 90.0 and -180.0 <= longitude <= 180.0):
            raise ValueError(
                f"geodetic origin ({latitude}, {longitude}) out of range (or not finite)"
            )
        infos = query_utm_crs_info(
            datum_name="WGS 84",
            area_of_interest=AreaOfInterest(longitude, latitude, longitude, latitude),
        )
        if not infos:
            raise ValueError(f"no UTM zone for ({latitude}, {longitude})")
        self.crs = CRS.from_epsg(int(infos[0].code))
        self.zone = self.crs.utm_zone
        self._forward = Transformer.from_crs("EPSG:4326", self.crs, always_xy=True)
        self._inverse = Transformer.from_crs(self.crs, "EPSG:4326", always_xy=True)
        self.latitude, self.longitude, self.altitude = latitude, longitude, altitude
        self.origin_east, self.origin_north = self._forward.transform(longitude, latitude)

    def forward(self, latitude: float, longitude: float) -> tuple[float, float]:
        """``(east, north)`` in metres from the origin (UTM of the origin's zone)."""
        east, north = self._forward.transform(longitude, latitude)
        return east - self.origin_east, north - self.origin_north

    def inverse(self, east: float, north: float) -> tuple[float, float]:
        """``(latitude, longitude)`` of a point ``east``, ``north`` metres from the origin."""
        lon, lat = self._inverse.transform(east + self.origin_east, north + self.origin_north)
        return lat, lon
