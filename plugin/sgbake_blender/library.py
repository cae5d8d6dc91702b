"""Loads libsgbake on first use and keeps it, for the operators and the panel.

The library is not loaded at register time: a missing or broken library must not make
enabling the add-on fail, it becomes an error report when baking and a line in the panel.
Where it is looked for: the add-on preferences' Library path, then $SGBAKE_LIBRARY, then
libsgbake.so in the add-on's folder, then the system library path (capi.candidate_paths).

A loaded library stays loaded (a shared library cannot be unloaded safely): the cache holds
one per preferences path and environment value. A failure is remembered for the panel, which
redraws often, but every bake tries again, so fixing the path needs no restart.
"""

import os

import bpy

from . import capi

_cache = {}  # (preferences path, $SGBAKE_LIBRARY) -> ctypes.CDLL or capi.SgbakeError


def preferences_path(context):
    """The Library path of the add-on preferences, absolute; "" when unset or when the add-on
    was registered without being enabled in the Preferences (e.g. by a script). Raises
    capi.SgbakeError for a path relative to an unsaved .blend file."""
    addon = context.preferences.addons.get(__package__)
    if addon is None or addon.preferences is None:
        return ""
    path = addon.preferences.library_path
    if not path:
        return ""
    if path.startswith("//") and not bpy.data.filepath:
        # bpy.path.abspath would leave a bare file name, which the system's search resolves.
        raise capi.SgbakeError(f"the add-on preferences' Library path '{path}' is relative to "
                               "the .blend file, which is not saved yet")
    return os.path.abspath(bpy.path.abspath(path))  # '//' is relative to the .blend file


def get(context, retry=True):
    """The loaded library. Raises capi.SgbakeError when it cannot be loaded; with
    retry=False a remembered failure is raised again without trying."""
    key = (preferences_path(context), os.environ.get(capi.LIBRARY_ENV, ""))
    cached = _cache.get(key)
    if isinstance(cached, capi.SgbakeError):
        if not retry:
            raise cached
    elif cached is not None:
        return cached
    try:
        lib = capi.load_library(key[0] or None, "the add-on preferences' Library")
    except capi.SgbakeError as exc:
        _cache[key] = exc
        raise
    _cache[key] = lib
    return lib


def describe(context):
    """One line for the panel: "libsgbake 0.2.0" or the reason it cannot be loaded."""
    try:
        return True, f"libsgbake {capi.version(get(context, retry=False))}"
    except capi.SgbakeError as exc:
        return False, str(exc)
