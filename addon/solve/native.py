"""Access to the compiled solver module `_radiosity`.

The module is a binary built for one Python version and linked against the
system's shared libraries, so importing it can fail on a machine it was not
built for. Registration must not depend on it (the panel should still appear
and explain the problem), so the import is attempted lazily, once, and the
error is kept to be reported by whoever needs the solver, with what to do
about it: rebuild, in a source build; reinstall the right zip, otherwise.
"""

import importlib
import pathlib
import platform
import re
import sys

# The add-on's package (radiosity, or bl_ext.user_default.radiosity), whose
# folder holds the compiled modules, one per Python version.
PACKAGE = __package__.rpartition(".")[0]
FOLDER = pathlib.Path(__file__).resolve().parent.parent

_module = None
_error = None
_advice = None


class NativeUnavailable(RuntimeError):
    """The compiled module could not be imported; the message says why."""


def load():
    """Return the `_radiosity` module, importing it on first use.

    Raises NativeUnavailable with a message fit for a user report.
    """
    global _module, _error, _advice
    if _module is None and _error is None:
        try:
            _module = importlib.import_module("._radiosity", PACKAGE)
        except ImportError as err:
            _advice = what_to_do(source_build())
            _error = "Radiosity native module could not be loaded: %s (%s)" % (err, _advice)
    if _module is None:
        raise NativeUnavailable(_error)
    return _module


def source_build(folder=None):
    """Whether the package runs from a source build (BUILD/addon/radiosity, with
    BUILD/CMakeCache.txt) rather than from an installed zip."""
    folder = pathlib.Path(folder or FOLDER).resolve()
    return (folder.parent.parent / "CMakeCache.txt").is_file()


def what_to_do(from_source):
    """What a user can do about a module that does not load: rebuild (a source build)
    or install the zip made for their Blender (an installed zip)."""
    built, running = _built_for(), "%d.%d" % sys.version_info[:2]
    if from_source:
        return ("it is built for Python %s; rebuild the add-on with `make` for this Blender, "
                "whose Python is %s" % (built, running))
    here = "Python %s" % running
    if (platform.system(), platform.machine()) != ("Linux", "x86_64"):
        here += " on %s %s" % (platform.system(), platform.machine())
    return ("this copy is built for Linux x64 and Python %s, and this Blender runs %s. "
            "Reinstall the add-on from the zip for Linux x64 and your Blender: "
            "radiosity-%s-linux_x64.zip, the same for every Blender from 3.4 (an extension "
            "in 4.2 and later, an add-on before). It needs a Blender "
            "whose Python is %s; others need a build of their own (README, "
            "\"Which Blender a build works in\")" % (built, here, _version(), built))


def error():
    """The import error message, or None when the module loaded (or was never tried)."""
    return _error


def advice():
    """What to do about the import error, or None when the module loaded (or was never tried)."""
    return _advice


def _version():
    package = sys.modules.get(PACKAGE)
    version = getattr(package, "bl_info", {}).get("version")
    return ".".join(map(str, version)) if version else "VERSION"


def loaded():
    """The module, or None if it cannot be loaded (for what only adds detail, such
    as the panel's reading of Quality)."""
    try:
        return load()
    except NativeUnavailable:
        return None


def version():
    """The native module's version string, or None if it cannot be loaded."""
    try:
        return load().__version__
    except NativeUnavailable:
        return None


def _built_for():
    # The interpreter tag is part of each module's file name
    # (_radiosity.cpython-311-x86_64-linux-gnu.so), which survives a failed import;
    # the package holds one module per Python version it serves.
    versions = sorted({tuple(map(int, match.groups()))
                       for path in FOLDER.glob("_radiosity*.so")
                       for match in [re.search(r"cpython-(\d)(\d+)", path.name)] if match})
    if not versions:
        return "an unknown version (no _radiosity*.so next to the add-on)"
    names = ["%d.%d" % v for v in versions]
    return names[0] if len(names) == 1 else "%s or %s" % (", ".join(names[:-1]), names[-1])
