"""Blender's command line for bpy, Blender as a Python module (tools/blenders.py).

    BUILD/blenders/4.5/bin/blender -b --factory-startup [FILE.blend] \
        [--addons a,b] [--python-exit-code N] [--python SCRIPT | --python-expr EXPR]... [-- ARGS]

The options the project's scripts and tests give a Blender, with Blender's
meaning: the file is opened and the scripts run in the order given, `sys.argv`
is the whole command line (scripts read their own arguments after `--`), an
exception in a script exits with the --python-exit-code (else the next argument
runs), `sys.exit` in a script ends the process with its code. bpy has no
window, so options that need one (--enable-event-simulate, running without -b)
are refused with a message. `bpy.app.binary_path`, empty in bpy, is set to this
command, so a script that starts another Blender starts this one.
"""

import os
import runpy
import sys
import traceback

USAGE = __doc__.split("\n\n")[1]
# Options that take a value, and those that only switch something.
WITH_VALUE = {"--python", "-P", "--python-expr", "--python-exit-code", "--addons"}
SWITCHES = {"-b", "--background", "--factory-startup", "-noaudio"}


class UsageError(Exception):
    pass


def parse(argv):
    """[(option, value)] in order, for the options before `--`."""
    if "--" in argv:
        argv = argv[:argv.index("--")]
    steps, i = [], 0
    while i < len(argv):
        arg = argv[i]
        if arg in WITH_VALUE:
            if i + 1 >= len(argv):
                raise UsageError("%s needs a value" % arg)
            steps.append((arg, argv[i + 1]))
            i += 2
            continue
        if arg in SWITCHES or arg in ("-v", "--version"):
            steps.append((arg, None))
        elif arg.startswith("-"):
            raise UsageError("option %s is not available in bpy (Blender as a Python module)" % arg)
        else:
            steps.append(("file", arg))
        i += 1
    if not any(option in ("-b", "--background", "-v", "--version") for option, _ in steps):
        raise UsageError("bpy has no window: run it with --background (-b)")
    return steps


def run_script(option, value):
    """Run one --python file or --python-expr as Blender does, as __main__."""
    if option == "--python-expr":
        exec(compile(value, "<string>", "exec"), {"__name__": "__main__"})
    else:
        runpy.run_path(value, run_name="__main__")


def main():
    argv = sys.argv[1:]
    try:
        steps = parse(argv)
    except UsageError as err:
        sys.stderr.write("blender (bpy): %s\n\n%s\n" % (err, USAGE))
        return 2
    import bpy  # after the arguments are known good: importing takes seconds
    import addon_utils

    if any(option in ("-v", "--version") for option, _ in steps):
        print("Blender %s (bpy)" % bpy.app.version_string)
        return 0
    bpy.app.binary_path = os.path.abspath(sys.argv[0])
    sys.argv = [bpy.app.binary_path] + argv  # what scripts see in Blender
    options = dict(steps)
    exit_code = int(options.get("--python-exit-code", 0))
    if "--factory-startup" in options:
        bpy.ops.wm.read_factory_settings(use_empty=False)
    for name in filter(None, options.get("--addons", "").split(",")):
        addon_utils.enable(name, default_set=True)
    for option, value in steps:
        if option == "file":
            bpy.ops.wm.open_mainfile(filepath=value)
        elif option in ("--python", "-P", "--python-expr"):
            try:
                run_script(option, value)
            except SystemExit:
                raise
            except BaseException:
                traceback.print_exc()
                if exit_code:
                    return exit_code
    return 0


if __name__ == "__main__":
    sys.exit(main())
