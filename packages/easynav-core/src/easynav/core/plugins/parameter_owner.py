"""ParameterOwner: anything that declares parameters as data (plugins, sub-plugins, filters)."""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Mapping
from typing import Any, ClassVar

from easynav.core.plugins.declarations import (
    Param,
    ParameterValueError,
    ParameterValues,
    declared_names,
    merge_declarations,
    read_parameters,
)


class ParameterOwner:
    """Parameters declared once, in ``PARAMETERS``, read under a prefix, changed at runtime.

    Every plugin is one (through :class:`~easynav.core.plugins.MethodBase`); so is a sub-plugin
    that is not a full plugin (a costmap filter, a recovery evaluator): it declares
    ``PARAMETERS`` and calls :meth:`read_declared_parameters` with its host's
    ``ParameterAccess`` and the prefix ``<alias>.<sub_alias>``, then reads
    ``self.params.<name>``. Hosts route a runtime change of ``<prefix>.<name>`` to
    :meth:`validate_parameter` then :meth:`apply_parameter` (see :meth:`parameter_owners`).

    Thread contract: ``read_declared_parameters`` in the configuring thread;
    ``validate_parameter``/``apply_parameter`` in the thread that changes the parameter (a ROS
    parameter service callback, or the configuring thread); values are replaced whole, so a
    cycle reading ``self.params`` sees either the old or the new value.
    """

    #: The owner's parameters (see :class:`Param`); a subclass's replace its bases' of the name.
    PARAMETERS: ClassVar[tuple[Param, ...]] = ()
    #: Parameters every instance of the family has, before each class's own (rt_freq, freq).
    BASE_PARAMETERS: ClassVar[tuple[Param, ...]] = ()
    #: Deprecated parameters a family still accepts, listed after every class's own.
    DEPRECATED_PARAMETERS: ClassVar[tuple[Param, ...]] = ()
    #: Keys accepted under the owner's prefix without a declaration (``plugin``: the plugin
    #: name, read by the host).
    ACCEPTED_KEYS: ClassVar[tuple[str, ...]] = ("plugin",)
    #: For an owner that hosts sub-plugins: each parameter listing sub-plugin aliases and the
    #: plugin kind (``PluginKind``) of those aliases, e.g. ``{"filters": COSTMAP_FILTER}``. The
    #: sub-plugin of alias ``a`` is named by ``a.plugin`` and reads its parameters under
    #: ``<prefix>.a.``; :meth:`unknown_parameter_keys` checks them with its class.
    SUB_PLUGIN_LISTS: ClassVar[dict[str, Any]] = {}

    params: ParameterValues
    parameter_prefix: str = ""

    # -- declarations --------------------------------------------------------------------------
    @classmethod
    def parameter_declarations(cls) -> tuple[Param, ...]:
        """Every parameter of this class: the family's base ones, then each class's own (base
        classes first; a subclass's declaration replaces a base's of the same name), then the
        family's deprecated ones."""
        groups = [cls.BASE_PARAMETERS]
        for klass in reversed(cls.__mro__):
            own = klass.__dict__.get("PARAMETERS")
            if own:
                groups.append(own)
        own = merge_declarations(groups)
        names = {param.name for param in own}
        return own + tuple(p for p in cls.DEPRECATED_PARAMETERS if p.name not in names)

    @classmethod
    def parameter_declaration(cls, name: str) -> Param | None:
        """The declaration of ``name`` (current or deprecated name), or None."""
        for param in cls.parameter_declarations():
            if name == param.name or name in param.deprecated:
                return param
        return None

    @classmethod
    def unknown_parameter_keys(cls, keys: Mapping[str, Any]) -> list[tuple[str, str | None]]:
        """Keys of a params file under this owner's prefix (relative names, with their values)
        that nothing declares: ``(key, closest declared name or None)`` each.

        Keys under a sub-plugin alias (see :attr:`SUB_PLUGIN_LISTS`) are checked by the class
        its ``<alias>.plugin`` names (not checked when that plugin is not installed: configure
        reports it).
        """
        from easynav.core.plugins.discovery import load_plugin_class

        sub_aliases = {
            alias: kind
            for name, kind in cls.SUB_PLUGIN_LISTS.items()
            for alias in (keys.get(name) or [])
            if isinstance(alias, str)
        }
        known = declared_names(cls.parameter_declarations()) | set(cls.ACCEPTED_KEYS)
        unknown = [
            (key, closest_name(key, known)) for key in keys
            if key not in known and key.split(".", 1)[0] not in sub_aliases
        ]
        for alias, kind in sub_aliases.items():
            prefix = f"{alias}."
            sub = {k[len(prefix):]: v for k, v in keys.items() if k.startswith(prefix)}
            try:
                sub_cls = load_plugin_class(kind, str(sub.get("plugin", "")), f"{alias}.plugin")
            except (LookupError, ImportError):
                continue
            for key, closest in sub_cls.unknown_parameter_keys(sub):
                unknown.append((prefix + key, None if closest is None else prefix + closest))
        return unknown

    # -- reading -------------------------------------------------------------------------------
    def read_declared_parameters(self, access: Any, prefix: str, warn: Any = None) -> None:
        """Declare and read every declared parameter under ``prefix`` into ``self.params``.

        Raises :class:`ParameterValueError` naming the first broken parameter.
        """
        self.parameter_prefix = prefix
        self.params = read_parameters(self.parameter_declarations(), access, prefix, warn)

    # -- runtime changes -----------------------------------------------------------------------
    def validate_parameter(self, name: str, value: Any) -> Any:
        """A runtime change of ``<prefix>.<name>`` checked against its declaration: the
        converted value, or :class:`ParameterValueError` with the reason (the host refuses it)."""
        param = self.parameter_declaration(name)
        full = f"{self.parameter_prefix}.{name}" if self.parameter_prefix else name
        if param is None:
            raise ParameterValueError(f"{full}: unknown parameter")
        if not param.dynamic:
            raise ParameterValueError(f"{full}: cannot change at runtime (reconfigure instead)")
        return param.convert(value, full)

    def apply_parameter(self, name: str, value: Any) -> None:
        """Store a validated runtime change and tell the owner (:meth:`on_parameter_changed`)."""
        param = self.parameter_declaration(name)
        key = param.name if param is not None else name
        self.params.set(key, value)
        self.on_parameter_changed(key, value)

    def on_parameter_changed(self, name: str, value: Any) -> None:
        """A parameter changed at runtime (already validated and stored in ``self.params``).
        Owners that read ``self.params`` every cycle need nothing here; those that derive
        state from a parameter rebuild it."""

    def sub_plugins(self) -> Iterable[ParameterOwner]:
        """The sub-plugins this owner has loaded (none by default; hosts of sub-plugins return
        theirs)."""
        return ()

    def parameter_owners(self) -> list[tuple[str, ParameterOwner]]:
        """``(prefix, owner)`` of this owner and of every sub-plugin it hosts, so that a host
        node routes ``<prefix>.<name>`` changes to the right one (longest prefix first)."""
        owners: list[tuple[str, ParameterOwner]] = [(self.parameter_prefix, self)]
        for sub in self.sub_plugins():
            owners.extend(sub.parameter_owners())
        return owners


def closest_name(name: str, known: Iterable[str]) -> str | None:
    """The declared name closest to a misspelt ``name`` (None when nothing is close)."""
    matches = difflib.get_close_matches(name, sorted(known), n=1, cutoff=0.6)
    return matches[0] if matches else None
