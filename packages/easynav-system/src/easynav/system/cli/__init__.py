"""The ``easynav`` command."""
