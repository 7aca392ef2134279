"""The add-on's layout holds (addon/: read, model, solve, write, ui): model/
imports in plain Python, and what a solve imports (solve/pipeline.py and all
it reaches) leaves out the glTF export operator and the interface.

run_tests.py puts build/addon/radiosity on sys.path: the assembled package.
"""

import ast
import importlib
import pathlib
import sys
import unittest

import model

PACKAGE = pathlib.Path(model.__file__).resolve().parent.parent  # build/addon/radiosity


def imported_modules(path):
    """The package's modules `path` imports ('write.bake', 'compat', ...)."""
    here = path.relative_to(PACKAGE).parent.parts
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = list(here[:len(here) - (node.level - 1)]) + (node.module.split(".") if node.module else [])
            for alias in node.names:
                name = ".".join(base + [alias.name])
                found.add(name if (PACKAGE / (name.replace(".", "/") + ".py")).exists() else ".".join(base))
    return {m for m in found if m}


def reached(start):
    """Every module of the package `start` imports, directly or not."""
    seen, todo = set(), [start]
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        path = PACKAGE / (name.replace(".", "/") + ".py")
        if not path.exists():
            path = PACKAGE / name.replace(".", "/") / "__init__.py"
        todo += sorted(imported_modules(path))
    return seen


class Layout(unittest.TestCase):
    def test_the_model_imports_without_blender(self):
        names = sorted(p.stem for p in (PACKAGE / "model").glob("*.py") if p.stem != "__init__")
        self.assertIn("findings", names)
        for name in names:
            importlib.import_module("model." + name)
        self.assertNotIn("bpy", sys.modules)

    def test_the_model_imports_nothing_else_of_the_add_on(self):
        for path in (PACKAGE / "model").glob("*.py"):
            outside = {m for m in imported_modules(path) if not m.startswith("model")}
            self.assertEqual(outside, set(), path.name)

    def test_a_solve_does_not_import_the_gltf_export_or_the_interface(self):
        modules = reached("solve.pipeline")
        self.assertIn("write.game_ready", modules)  # the game-ready bake it does use
        self.assertIn("read.export", modules)
        self.assertNotIn("write.gltf_export", modules)
        self.assertEqual({m for m in modules if m.startswith("ui")}, set())


if __name__ == "__main__":
    unittest.main()
