"""MapFormatError: a map file that cannot be read, naming the file and the line or key."""

from __future__ import annotations


class MapFormatError(ValueError):
    """A ``.map`` file, a ROS map YAML or its image is malformed.

    The message names the file and, where it applies, the line (``file.map:2: ...``) or the YAML
    key at fault. A missing file raises :class:`FileNotFoundError` instead (naming the file).
    """
