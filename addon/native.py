"""Access to the compiled solver module `_radiosity`.

The module is a binary built for one Python version and linked against the
system's shared libraries, so importing it can fail on a machine it was not
built for. Registration must not depend on it (the panel should still appear
and explain the problem), so the import is attempted lazily, once, and the
error is kept to be reported by whoever needs the solver.
"""

import importlib
import pathlib
import re
import sys

_module = None
_error = None


class NativeUnavailable(RuntimeError):
    """The compiled module could not be imported; the message says why."""


def load():
    """Return the `_radiosity` module, importing it on first use.

    Raises NativeUnavailable with a message fit for a user report.
    """
    global _module, _error
    if _module is None and _error is None:
        try:
            _module = importlib.import_module("._radiosity", __package__)
        except ImportError as err:
            _error = (
                "Radiosity native module could not be loaded: %s "
                "(it is built for Python %s; rebuild the add-on with `make` "
                "for this Blender, whose Python is %d.%d)"
                % (err, _built_for(), *sys.version_info[:2])
            )
    if _module is None:
        raise NativeUnavailable(_error)
    return _module


def error():
    """The import error message, or None when the module loaded (or was never tried)."""
    return _error


def version():
    """The native module's version string, or None if it cannot be loaded."""
    try:
        return load().__version__
    except NativeUnavailable:
        return None


def _built_for():
    # The interpreter tag is part of the extension's file name
    # (_radiosity.cpython-311-x86_64-linux-gnu.so), which survives a failed import.
    for path in pathlib.Path(__file__).parent.glob("_radiosity*.so"):
        match = re.search(r"cpython-(\d)(\d+)", path.name)
        if match:
            return "%s.%s" % match.groups()
    return "an unknown version (no _radiosity*.so next to the add-on)"
