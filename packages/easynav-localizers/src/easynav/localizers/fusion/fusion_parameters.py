"""Parameters of the fusion localizer: robot_localization's names, per filter and per input."""

from __future__ import annotations

import re
import sys
from typing import Any

from easynav.core.plugins import Param
from easynav.core.plugins.declarations import ParameterValueError, read_parameters
from easynav.localizers.fusion.fusion_input import INPUT_KINDS, FusionInput
from easynav.localizers.fusion.ukf_filter import (
    DEFAULT_INITIAL_COVARIANCE,
    DEFAULT_PROCESS_NOISE,
)

#: The two filters: parameter prefix, output NavState key and frame role.
FILTER_PREFIXES = ("global_filter", "local_filter")
#: robot_localization's "no gate" (std::numeric_limits<double>::max()).
NO_THRESHOLD = sys.float_info.max
_STATIC = {"dynamic": False}  # the filters are built at configure time
_COMPAT = "accepted for params-file compatibility; no effect here"

#: Per-filter parameters (relative to ``<alias>.<global|local>_filter.``).
FILTER_PARAMETERS = (
    Param("alpha", 0.001, "UKF sigma-point spread", gt=0.0, **_STATIC),
    Param("kappa", 0.0, "UKF secondary scaling", **_STATIC),
    Param("beta", 2.0, "UKF prior-distribution weight (2: Gaussian)", ge=0.0, **_STATIC),
    Param("two_d_mode", False, "hold z, roll, pitch and their rates at zero", **_STATIC),
    Param("predict_to_current_time", False, "predict the output to the current time",
          **_STATIC),
    Param("publish_tf", True, "global filter: broadcast map → odom", **_STATIC),
    Param("gravitational_acceleration", 9.80665, "removed from IMU accelerations when asked",
          "m/s²", ge=0.0, **_STATIC),
    Param("initial_state", [0.0] * 15, "initial 15-state", **_STATIC),
    Param("process_noise_covariance", list(DEFAULT_PROCESS_NOISE),
          "process noise per second: 15 diagonal values or 225 (15×15)", **_STATIC),
    Param("initial_estimate_covariance", list(DEFAULT_INITIAL_COVARIANCE),
          "initial covariance: 15 diagonal values or 225 (15×15)", **_STATIC),
    Param("frequency", 30.0, "the filter runs at the plugin's rt_freq; " + _COMPAT, "Hz", gt=0.0,
          **_STATIC),
    Param("sensor_timeout", 0.0, _COMPAT, "s", ge=0.0, **_STATIC),
    Param("publish_acceleration", False, _COMPAT, **_STATIC),
    Param("permit_corrected_publication", False, _COMPAT, **_STATIC),
    Param("smooth_lagged_data", False, _COMPAT, **_STATIC),
    Param("history_length", 0.0, _COMPAT, "s", ge=0.0, **_STATIC),
    Param("reset_on_time_jump", False, _COMPAT, **_STATIC),
    Param("use_control", False, _COMPAT, **_STATIC),
    Param("stamped_control", True, _COMPAT, **_STATIC),
    Param("control_timeout", 0.0, _COMPAT, "s", **_STATIC),
    Param("control_config", [False] * 6, _COMPAT, **_STATIC),
    Param("acceleration_limits", [1.3, 0.0, 0.0, 0.0, 0.0, 3.4], _COMPAT, **_STATIC),
    Param("deceleration_limits", [1.3, 0.0, 0.0, 0.0, 0.0, 4.5], _COMPAT, **_STATIC),
    Param("acceleration_gains", [1.0] * 6, _COMPAT, **_STATIC),
    Param("deceleration_gains", [1.0] * 6, _COMPAT, **_STATIC),
    Param("dynamic_process_noise_covariance", False, _COMPAT, **_STATIC),
    Param("disabled_at_startup", False, _COMPAT, **_STATIC),
    Param("print_diagnostics", False, _COMPAT, **_STATIC),
    Param("debug", False, _COMPAT, **_STATIC),
    Param("transform_time_offset", 0.0, _COMPAT, "s", **_STATIC),
    Param("transform_timeout", 0.0, _COMPAT, "s", **_STATIC),
    Param("map_frame", "map", "ignored: frames come from system_node", **_STATIC),
    Param("odom_frame", "odom", "ignored: frames come from system_node", **_STATIC),
    Param("base_link_frame", "base_link", "ignored: frames come from system_node", **_STATIC),
    Param("world_frame", "odom", "ignored: frames come from system_node", **_STATIC),
)

#: Suffixes each input kind accepts (after ``<kind>N``), with their declarations.
_THRESHOLD_DOC = "Mahalanobis gate (default: none)"


def _input_suffixes(kind: str) -> tuple[Param, ...]:
    # Which suffixes each kind has, as the original's ukf_wrapper.cpp declares them: odom, pose,
    # imu and gps have _differential/_relative; twist has neither; imuN_angular_velocity_...
    # is robot_localization's name of the original's imuN_twist_rejection_threshold.
    common = (
        Param("_config", [False] * 15, "which of the 15 state variables the input measures",
              **_STATIC),
        Param("_queue_size", 10, "messages kept between two cycles", ge=1, **_STATIC),
    )
    pose_like = (
        Param("_differential", False, "fuse the change between consecutive poses as a "
              "velocity (wins over _relative)", **_STATIC),
        Param("_relative", False, "poses relative to the input's first message", **_STATIC),
    )
    if kind == "odom":
        return common + pose_like + (
            Param("_pose_use_child_frame", False, "the pose is of the message's child_frame_id: "
                  "moved to the robot frame through TF (child → robot) before it is fused",
                  **_STATIC),
            Param("_pose_rejection_threshold", NO_THRESHOLD, _THRESHOLD_DOC, gt=0.0),
            Param("_twist_rejection_threshold", NO_THRESHOLD, _THRESHOLD_DOC, gt=0.0),
        )
    if kind in ("pose", "gps"):
        return common + pose_like + (
            Param("_rejection_threshold", NO_THRESHOLD, _THRESHOLD_DOC, gt=0.0),
        )
    if kind == "twist":
        return common + (Param("_rejection_threshold", NO_THRESHOLD, _THRESHOLD_DOC, gt=0.0),)
    return common + pose_like + (  # imu
        Param("_pose_rejection_threshold", NO_THRESHOLD, _THRESHOLD_DOC, gt=0.0),
        Param("_twist_rejection_threshold", NO_THRESHOLD,
              "angular velocity: " + _THRESHOLD_DOC, gt=0.0),
        Param("_angular_velocity_rejection_threshold", NO_THRESHOLD,
              "robot_localization's name of _twist_rejection_threshold", gt=0.0),
        Param("_linear_acceleration_rejection_threshold", NO_THRESHOLD, _THRESHOLD_DOC,
              gt=0.0),
        Param("_remove_gravitational_acceleration", False, "subtract gravity from the "
              "acceleration", **_STATIC),
    )


_INPUT_KEY = re.compile(r"^(?P<kind>odom|pose|twist|imu|gps)(?P<n>\d+)(?P<suffix>_\w+)?$")


def is_input_key(key: str) -> bool:
    """Whether ``key`` (relative to a filter prefix) names an input or one of its settings."""
    match = _INPUT_KEY.match(key)
    if match is None:
        return False
    suffix = match.group("suffix")
    return suffix is None or suffix in {p.name for p in _input_suffixes(match.group("kind"))}


def input_declarations(kind: str, index: int) -> tuple[Param, ...]:
    """Declarations of input ``<kind><index>`` (relative to the filter prefix)."""
    name = f"{kind}{index}"
    what = "not subscribed: the N-th GNSS of NavState group gnss" if kind == "gps" else "topic"
    return (Param(name, "", what, **_STATIC),) + tuple(
        Param(name + p.name, p.default, p.description, p.unit, gt=p.gt, ge=p.ge, dynamic=False)
        for p in _input_suffixes(kind)
    )


def read_inputs(access: Any, prefix: str, warn: Any = None) -> list[FusionInput]:
    """Inputs ``odom0, odom1, ..., gps0, ...`` set under ``prefix`` (numbered from 0 with no
    gap, as robot_localization reads them). Raises ParameterValueError naming the key.

    ``warn`` (a callable taking a message, optional) hears of an input with both
    ``_differential`` and ``_relative`` true: differential is used, as in the original.
    """
    inputs: list[FusionInput] = []
    for kind in INPUT_KINDS:
        n = 0
        while access.is_set(f"{prefix}.{kind}{n}"):
            values = read_parameters(input_declarations(kind, n), access, prefix)
            name = f"{kind}{n}"
            config = values[name + "_config"]
            if len(config) != 15:
                raise ParameterValueError(
                    f"{prefix}.{name}_config: {len(config)} values, expected 15"
                )
            source = FusionInput(kind, n, values[name], list(config),
                                 queue_size=values[name + "_queue_size"])
            source.differential = values.get(name + "_differential", False)
            source.relative = values.get(name + "_relative", False)
            if source.differential and source.relative:
                if warn is not None:
                    warn(f"{prefix}.{name}_differential and {prefix}.{name}_relative are both "
                         "true: differential is used")
                source.relative = False
            if kind == "odom":
                source.pose_use_child_frame = values[name + "_pose_use_child_frame"]
            if kind in ("odom", "imu"):
                source.pose_threshold = values[name + "_pose_rejection_threshold"]
            if kind == "odom":
                source.twist_threshold = values[name + "_twist_rejection_threshold"]
            if kind == "pose" or kind == "gps":
                source.pose_threshold = values[name + "_rejection_threshold"]
            if kind == "twist":
                source.twist_threshold = values[name + "_rejection_threshold"]
            if kind == "imu":
                source.twist_threshold = _imu_twist_threshold(access, prefix, name, values)
                source.acceleration_threshold = values[
                    name + "_linear_acceleration_rejection_threshold"]
                source.remove_gravitational_acceleration = values[
                    name + "_remove_gravitational_acceleration"]
            inputs.append(source)
            n += 1
    return inputs


def _imu_twist_threshold(access: Any, prefix: str, name: str, values: Any) -> float:
    """The angular-velocity gate of IMU ``name``: ``_twist_rejection_threshold`` (the
    original's name) or ``_angular_velocity_rejection_threshold`` (robot_localization's); both
    set to different values is an error naming both."""
    original = f"{name}_twist_rejection_threshold"
    upstream = f"{name}_angular_velocity_rejection_threshold"
    set_original = access.is_set(f"{prefix}.{original}")
    set_upstream = access.is_set(f"{prefix}.{upstream}")
    if set_original and set_upstream and values[original] != values[upstream]:
        raise ParameterValueError(
            f"{prefix}.{original} = {values[original]} and {prefix}.{upstream} = "
            f"{values[upstream]}: two names of the same gate, set to different values; "
            "set one of them"
        )
    return values[upstream] if set_upstream and not set_original else values[original]


def prefixed(prefix: str, declarations: tuple[Param, ...]) -> tuple[Param, ...]:
    """``declarations`` renamed ``<prefix>.<name>``."""
    return tuple(
        Param(f"{prefix}.{p.name}", p.default, p.description, p.unit, p.type, p.gt, p.ge, p.lt,
              p.le, p.choices, p.allow_nan, p.deprecated, p.dynamic)
        for p in declarations
    )
