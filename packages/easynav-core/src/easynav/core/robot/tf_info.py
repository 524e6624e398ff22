"""TFInfo: the frame names of one robot, shared by every EasyNav component."""

from __future__ import annotations

from dataclasses import dataclass

_FRAME_FIELDS = ("map_frame", "odom_frame", "robot_frame", "robot_footprint_frame", "world_frame")


@dataclass(frozen=True, slots=True)
class TFInfo:
    """The six frame parameters of ``system_node``; ``tf_prefix`` is applied to the five frames.

    With a non-empty ``tf_prefix`` every frame becomes ``"<tf_prefix>/<frame>"``. Applying it is
    idempotent (a frame already starting with ``"<tf_prefix>/"`` is kept), so a TFInfo can be
    built from raw parameters or copied with ``dataclasses.replace`` without doubling the prefix.

    Thread contract: immutable; share it freely. Exceptions: ``ValueError`` when a frame name is
    empty (a frame parameter set to "" would silently make every lookup fail).
    """

    map_frame: str = "map"
    odom_frame: str = "odom"
    robot_frame: str = "base_link"
    robot_footprint_frame: str = "base_footprint"
    world_frame: str = "earth"
    tf_prefix: str = ""

    def __post_init__(self) -> None:
        prefix = self.tf_prefix.strip("/")
        object.__setattr__(self, "tf_prefix", prefix)
        for name in _FRAME_FIELDS:
            frame = getattr(self, name)
            if not isinstance(frame, str) or not frame.strip("/"):
                raise ValueError(f"system_node.{name} = {frame!r}: a frame name cannot be empty")
            if prefix and not frame.startswith(prefix + "/"):
                object.__setattr__(self, name, f"{prefix}/{frame.lstrip('/')}")

    @classmethod
    def from_parameters(
        cls,
        tf_prefix: str = "",
        map_frame: str = "map",
        odom_frame: str = "odom",
        robot_frame: str = "base_link",
        robot_footprint_frame: str = "base_footprint",
        world_frame: str = "earth",
    ) -> TFInfo:
        """The TFInfo of ``system_node``'s parameters, prefix applied."""
        return cls(
            map_frame=map_frame,
            odom_frame=odom_frame,
            robot_frame=robot_frame,
            robot_footprint_frame=robot_footprint_frame,
            world_frame=world_frame,
            tf_prefix=tf_prefix,
        )
