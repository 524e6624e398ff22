"""CdrBuffer: the ROS 2 CDR (XCDR1) encoding of the NavMap message, natively."""

from __future__ import annotations

import struct

import numpy as np

from easynav.maps.map_format_error import MapFormatError


class CdrBuffer:
    """Reads or writes the plain CDR encoding that ROS 2 (rmw_fastrtps/cyclonedds) gives a
    message: a 4-byte encapsulation header (``00 01`` little endian, ``00 00`` big endian, two
    option bytes), then the fields in order, each primitive aligned to its size counted from the
    end of the header; strings are a uint32 length including the NUL, then the bytes and the
    NUL; sequences a uint32 count, then the elements (aligned only when there is one).

    Reading: ``CdrBuffer(data, source)`` then the ``read_*`` methods; every overrun raises
    :class:`MapFormatError` naming ``source``. Writing: ``CdrBuffer()`` then the ``write_*``
    methods and :meth:`getvalue`.

    Thread contract: one instance per thread. Exceptions: :class:`MapFormatError` (reading).
    """

    def __init__(self, data: bytes | None = None, source: str = "<bytes>") -> None:
        self.source = source
        if data is None:
            self._out = bytearray(b"\x00\x01\x00\x00")
            self._order = "<"
            return
        self._data = memoryview(data)
        if len(data) < 4:
            raise MapFormatError(f"{source}: CDR payload shorter than its 4-byte header")
        kind = bytes(data[:2])
        if kind == b"\x00\x01":
            self._order = "<"
        elif kind == b"\x00\x00":
            self._order = ">"
        else:
            raise MapFormatError(
                f"{source}: unknown CDR encapsulation {kind.hex()} (expected 0001 or 0000)"
            )
        self._pos = 4

    # -- reading --------------------------------------------------------------------------------
    def _align(self, size: int) -> None:
        self._pos += (-(self._pos - 4)) % size

    def _take(self, n: int, what: str) -> memoryview:
        if self._pos + n > len(self._data):
            raise MapFormatError(
                f"{self.source}: payload ends at byte {len(self._data)} while reading {what} "
                f"({n} bytes at {self._pos})"
            )
        out = self._data[self._pos : self._pos + n]
        self._pos += n
        return out

    def read(self, fmt: str, what: str):
        """One primitive (struct format letter)."""
        size = struct.calcsize(fmt)
        self._align(size)
        return struct.unpack(self._order + fmt, self._take(size, what))[0]

    def read_string(self, what: str) -> str:
        """A CDR string."""
        n = self.read("I", what)
        raw = bytes(self._take(n, what))
        return raw[:-1].decode("utf-8", "replace") if n else ""

    def read_array(self, dtype, what: str, limit: int | None = None) -> np.ndarray:
        """A sequence of primitives as a native-order numpy array."""
        dtype = np.dtype(dtype)
        n = self.read("I", what + " count")
        if limit is not None and n > limit:
            raise MapFormatError(f"{self.source}: {what} announces {n} elements (limit {limit})")
        if n == 0:
            return np.zeros(0, dtype=dtype)
        self._align(dtype.itemsize)
        raw = self._take(n * dtype.itemsize, what)
        return np.frombuffer(raw, dtype=dtype.newbyteorder(self._order)).astype(dtype)

    @property
    def remaining(self) -> int:
        """Bytes left after the read position."""
        return len(self._data) - self._pos

    # -- writing --------------------------------------------------------------------------------
    def _pad(self, size: int) -> None:
        self._out += b"\x00" * ((-(len(self._out) - 4)) % size)

    def write(self, fmt: str, value) -> None:
        """One primitive."""
        self._pad(struct.calcsize(fmt))
        self._out += struct.pack("<" + fmt, value)

    def write_string(self, value: str) -> None:
        """A CDR string."""
        raw = value.encode("utf-8") + b"\x00"
        self.write("I", len(raw))
        self._out += raw

    def write_array(self, values: np.ndarray, dtype) -> None:
        """A sequence of primitives (little endian)."""
        dtype = np.dtype(dtype)
        values = np.ascontiguousarray(values, dtype=dtype.newbyteorder("<"))
        self.write("I", len(values))
        if len(values):
            self._pad(dtype.itemsize)
            self._out += values.tobytes()

    def getvalue(self) -> bytes:
        """The encoded payload (header included)."""
        return bytes(self._out)
