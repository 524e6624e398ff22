"""CompiledKernel: a numba-compiled search imported on first use, or None without numba."""

from __future__ import annotations

import importlib

from easynav.common.compiled_kernels import compile_in_child


class CompiledKernel:
    """The function ``name`` of the module ``module`` (a numba ``@njit`` kernel), imported
    (and so compiled or loaded from numba's cache) the first time it is asked for.

    ``get()`` is None when the module cannot be imported (numba is not installed: the caller
    runs its pure-Python reference instead). Any thread: at worst two threads import the
    module at once, which Python's import lock makes safe.
    """

    def __init__(self, module: str, name: str) -> None:
        self.module = module
        self.name = name
        self._kernel = None  # None: not tried yet; False: unavailable

    def get(self):
        """The kernel, or None without numba."""
        if self._kernel is None:
            try:
                kernel = getattr(importlib.import_module(self.module), self.name)
                self._kernel = compile_in_child(kernel, f"{self.module}:{self.name}")
            except ImportError:
                self._kernel = False
        return self._kernel or None

    def available(self) -> bool:
        """Whether the compiled kernel can be used."""
        return self.get() is not None
