"""ConfigurationFingerprint: the SHA-256 of every effective parameter of every EasyNav node,
computed on each successful configure, so that the same fingerprint means the same
configuration (defaults included) and a single changed parameter gives a different one."""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

#: ROS 2 parameter type names (rcl_interfaces/ParameterType), as written in the text.
#: ``not_set`` (a parameter declared without a value) is written ``null``.
PARAMETER_TYPES = (
    "not_set",
    "bool",
    "integer",
    "double",
    "string",
    "byte_array",
    "bool_array",
    "integer_array",
    "double_array",
    "string_array",
)

# Characters Python's str.splitlines() (and some editors) take as line breaks but JSON leaves
# as they are: escaped too, so no string value can look like two lines to any tool.
_EXTRA_LINE_BREAKS = {"\x85": "\\u0085", "\u2028": "\\u2028", "\u2029": "\\u2029"}


def _quote(text: str) -> str:
    """A string as a double-quoted JSON literal, with every line break escaped."""
    quoted = json.dumps(text, ensure_ascii=False)
    for char, escape in _EXTRA_LINE_BREAKS.items():
        quoted = quoted.replace(char, escape)
    return quoted


def _format_double(value: object, where: str) -> str:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise TypeError(f"{where}: {value!r} is not a double")
    # repr() is the shortest text that reads back as the same double (Python >= 3.1);
    # 'nan', 'inf' and '-inf' are written as such.
    return repr(float(value))


def _format_integer(value: object, where: str) -> str:
    if isinstance(value, bool) or not isinstance(value, int):
        raise TypeError(f"{where}: {value!r} is not an integer")
    return str(int(value))


def _format_bool(value: object, where: str) -> str:
    if not isinstance(value, bool):
        raise TypeError(f"{where}: {value!r} is not a bool")
    return "true" if value else "false"


def _format_string(value: object, where: str) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{where}: {value!r} is not a string")
    return _quote(value)


def _format_byte(value: object, where: str) -> str:
    if isinstance(value, bytes | bytearray) and len(value) == 1:
        return str(value[0])
    if isinstance(value, int) and not isinstance(value, bool) and 0 <= value <= 255:
        return str(value)
    raise TypeError(f"{where}: {value!r} is not a byte")


_SCALAR_FORMATS = {
    "bool": _format_bool,
    "integer": _format_integer,
    "double": _format_double,
    "string": _format_string,
}


def format_value(type_name: str, value: object, where: str = "parameter") -> str:
    """The text of one parameter value. ``TypeError``/``ValueError`` naming ``where``."""
    if type_name == "not_set":
        if value is not None:
            raise TypeError(f"{where}: {value!r} given for a parameter of type not_set")
        return "null"
    if type_name in _SCALAR_FORMATS:
        return _SCALAR_FORMATS[type_name](value, where)
    if type_name == "byte_array":
        if isinstance(value, bytes | bytearray):
            items = [str(b) for b in value]
        else:
            items = [_format_byte(v, where) for v in _sequence(value, where)]
        return "[" + ", ".join(items) + "]"
    if type_name.endswith("_array") and type_name[: -len("_array")] in _SCALAR_FORMATS:
        formatter = _SCALAR_FORMATS[type_name[: -len("_array")]]
        return "[" + ", ".join(formatter(v, where) for v in _sequence(value, where)) + "]"
    raise ValueError(f"{where}: unknown parameter type {type_name!r} (one of {PARAMETER_TYPES})")


def _sequence(value: object, where: str) -> Iterable[object]:
    if isinstance(value, str | bytes) or not isinstance(value, Iterable):
        raise TypeError(f"{where}: {value!r} is not an array")
    # numpy arrays (rclpy returns array.array / numpy for some types) become Python scalars.
    return [v.item() if hasattr(v, "item") else v for v in value]  # type: ignore[union-attr]


def _safe_namespace(namespace: str) -> str:
    """'/robot1' -> 'robot1', '/a/b' -> 'a_b', '/' or '' -> ''."""
    return "_".join(part for part in namespace.split("/") if part)


def ros_log_dir() -> Path:
    """The ROS log directory: $ROS_LOG_DIR, else $ROS_HOME/log, else ~/.ros/log.

    As rcl_logging does, an empty variable counts as unset and ``~`` is expanded.
    """
    log_dir = os.environ.get("ROS_LOG_DIR", "")
    if log_dir:
        return Path(log_dir).expanduser()
    ros_home = os.environ.get("ROS_HOME", "")
    if ros_home:
        return Path(ros_home).expanduser() / "log"
    return Path.home() / ".ros" / "log"


class ConfigurationFingerprint:
    """The configuration's text (sorted, typed, one parameter per line) and its SHA-256.

    Built from ``(node, name, type_name, value)`` tuples, one per parameter of every EasyNav
    node, with the ROS type names of :data:`PARAMETER_TYPES`. Each line reads
    ``node/name (type) = value``: bools ``true``/``false``, integers in decimal, doubles in
    their shortest round-trip form (``repr``), strings double-quoted and escaped as JSON (so a
    newline or a quote inside cannot fake another line or value), arrays like ``["ctrl"]`` or
    ``[1.0, 2.5]``, byte arrays as decimal bytes. Lines are sorted by node, then name, and each
    ends with a newline; :attr:`hash` is the SHA-256 of that UTF-8 text, so ``sha256sum`` of a
    saved file gives the hash in its name.

    Thread contract: built and used by the configuring thread (system_node's on_configure);
    immutable afterwards except for the result of :meth:`save`.
    Exceptions: ``ValueError``/``TypeError`` naming the parameter for an unknown type, a value
    of the wrong type, a duplicate parameter or a node/name containing a line break.
    """

    def __init__(self, parameters: Iterable[tuple[str, str, str, object]]) -> None:
        lines: dict[tuple[str, str], str] = {}
        for node, name, type_name, value in parameters:
            where = f"{node}/{name}"
            if any(c in where for c in "\n\r\x85\u2028\u2029"):
                raise ValueError(f"parameter {where!r}: a line break in a node or parameter name")
            if (node, name) in lines:
                raise ValueError(f"parameter {where} given twice")
            text = format_value(type_name, value, where)
            lines[(node, name)] = f"{where} ({type_name}) = {text}\n"
        self.text = "".join(lines[key] for key in sorted(lines))
        self.hash = hashlib.sha256(self.text.encode("utf-8")).hexdigest()
        self.saved_path: Path | None = None
        self.save_warning: str | None = None

    def file_name(self, namespace: str = "") -> str:
        """``easynav_configuration_<hash>.txt`` or ``easynav_configuration_<ns>_<hash>.txt``."""
        ns = _safe_namespace(namespace)
        middle = f"{ns}_" if ns else ""
        return f"easynav_configuration_{middle}{self.hash}.txt"

    def save(self, log_dir: Path, namespace: str = "") -> tuple[Path | None, str | None]:
        """Save :attr:`text` in ``log_dir``; ``(path, None)`` or ``(None, warning)``.

        A file already there is not rewritten (same hash, same contents). The file is written
        to a temporary name and renamed, so a crash never leaves a partial file under the
        final name. Never raises: a failure returns a warning saying why.
        """
        path = Path(log_dir) / self.file_name(namespace)
        try:
            if not path.exists():
                path.parent.mkdir(parents=True, exist_ok=True)
                descriptor, temporary = tempfile.mkstemp(
                    prefix=".easynav_configuration_", suffix=".tmp", dir=path.parent
                )
                try:
                    with os.fdopen(descriptor, "w", encoding="utf-8", newline="") as file:
                        file.write(self.text)
                    os.chmod(temporary, 0o644)
                    os.replace(temporary, path)
                except BaseException:
                    Path(temporary).unlink(missing_ok=True)
                    raise
        except Exception as error:  # saving never stops EasyNav
            self.saved_path = None
            self.save_warning = f"could not save the configuration to {path}: {error}"
            return None, self.save_warning
        self.saved_path = path
        self.save_warning = None
        return path, None

    def topic_text(self) -> str:
        """The ``easynav_configuration`` message: ``# SHA-256: <hash>`` then the text."""
        return f"# SHA-256: {self.hash}\n{self.text}"

    def log_lines(
        self,
        plugins: Mapping[str, Sequence[tuple[str, str]]],
        saved_path: Path | None = None,
    ) -> list[str]:
        """The INFO log lines, in the layout of the original EasyNav's safety documentation::

            Configuration SHA-256: <hash>
              (<saved path>). Plugins:
              controller_node: ctrl [easynav_simple_controller/SimpleController]

        ``plugins``: ``{node: [(alias, plugin name), ...]}``, in the order given; a node with
        several plugins lists them separated by commas. ``saved_path`` defaults to the last
        :meth:`save`; when not saved, the second line says why.
        """
        path = saved_path if saved_path is not None else self.saved_path
        if path is not None:
            where = f"  ({path}). Plugins:"
        elif self.save_warning is not None:
            where = f"  (not saved: {self.save_warning}). Plugins:"
        else:
            where = "  (not saved). Plugins:"
        lines = [f"Configuration SHA-256: {self.hash}", where]
        for node, loaded in plugins.items():
            listed = ", ".join(f"{alias} [{plugin}]" for alias, plugin in loaded)
            lines.append(f"  {node}: {listed}" if listed else f"  {node}: (none)")
        return lines
