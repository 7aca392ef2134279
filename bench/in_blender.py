"""What the benchmarks that run inside Blender (contact_gap.py,
tessellated_room.py, window_speed.py) share: their options after `--`, the
add-on loaded from a build tree with the Cycles-agreement helpers of
tests/blender, and their tables written to <build>/bench."""

import argparse
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]


def arguments(prog, quick_help):
    parser = argparse.ArgumentParser(prog=prog)
    parser.add_argument("--build", default=str(ROOT / "build"), help="build tree (its addon/ is loaded)")
    parser.add_argument("--quick", action="store_true", help=quick_help)
    parser.add_argument("--images", help="write the reference and solution renders here as PNG")
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    return parser.parse_args(argv)


def load_addon(build):
    """Registers the add-on of `build` and returns its package; tests/blender goes on the path."""
    sys.path.insert(0, str(pathlib.Path(build).resolve() / "addon"))
    sys.path.insert(0, str(ROOT / "tests" / "blender"))
    import radiosity
    radiosity.register()
    return radiosity


def write_table(build, name, rows):
    """Prints the markdown table of `rows` and writes it to <build>/bench/<name>.md."""
    table = "\n".join(rows) + "\n"
    print(table)
    out = pathlib.Path(build).resolve() / "bench"
    out.mkdir(parents=True, exist_ok=True)
    (out / (name + ".md")).write_text(table)
