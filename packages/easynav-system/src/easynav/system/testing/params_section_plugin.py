"""A plugin configured from one node's section of a params file, as its node would do it.

The packages' tests use it to show that a section written for the original EasyNav (the
Kobuki playground's ``simple.params.yaml``) configures their plugin unchanged: the file goes to
rclpy with ``--params-file``, a node of the section's name reads it, and the plugin named under
``<alias>.plugin`` is loaded through its entry point and initialised from that node's parameters.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import yaml

from easynav.core.plugins import PluginContext
from easynav.core.plugins.discovery import load_plugin_class


@contextmanager
def plugin_from_params_section(
    params_text: str, node_name: str, kind: str, tmp_path: Path
) -> Iterator[tuple[Any, dict]]:
    """Yield ``(plugin, section)``: the first plugin of ``<node_name>.<kind>_types`` configured
    from ``params_text``, and the node's ``ros__parameters`` as plain YAML.

    ``kind`` is the plugin kind of :mod:`easynav.core.plugins.plugin_kinds` (``controller``,
    ``maps_manager``, ...); the node's list of aliases is ``<prefix>_types`` as the original
    names it (``controller_types``, ``map_types``, ...). Needs rclpy (it creates one context and
    one node, both shut down on exit). Raises what the plugin's ``initialize`` raises.
    """
    import rclpy

    from easynav.system.node_parameters import NodeParameters

    section = yaml.safe_load(params_text)[node_name]["ros__parameters"]
    types_key = next(key for key in section if key.endswith("_types"))
    alias = section[types_key][0]
    params_file = tmp_path / f"{node_name}.params.yaml"
    params_file.write_text(params_text)
    context = rclpy.Context()
    rclpy.init(args=["--ros-args", "--params-file", str(params_file)], context=context)
    try:
        node = rclpy.create_node(node_name, context=context)
        try:
            cls = load_plugin_class(kind, section[alias]["plugin"], f"{node_name}.{alias}.plugin")
            plugin = cls()
            plugin.initialize(
                PluginContext(parameters=NodeParameters(node), node=None,
                              namespace=f"seed_{node_name}"),
                alias,
            )
            yield plugin, section
        finally:
            node.destroy_node()
    finally:
        rclpy.shutdown(context=context)
