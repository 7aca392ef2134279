"""The C++ sources follow .clang-format (issue 14): clang-format 16, which
.ci/install-deps.sh installs, must leave every tracked .cpp and .h unchanged.
Fix a failure with `clang-format-16 -i FILE`.
"""

import pathlib
import shutil
import subprocess
import unittest

ROOT = pathlib.Path(__file__).resolve().parents[2]
CLANG_FORMAT = "clang-format-16"


def cpp_sources():
    listed = subprocess.run(["git", "ls-files", "*.cpp", "*.h"], cwd=ROOT, check=True, capture_output=True,
                            text=True).stdout.split()
    return [ROOT / name for name in listed]


class FormatTest(unittest.TestCase):
    def test_cpp_sources_follow_clang_format(self):
        tool = shutil.which(CLANG_FORMAT)
        self.assertIsNotNone(tool, "%s not found: bash .ci/install-deps.sh installs it" % CLANG_FORMAT)
        sources = cpp_sources()
        self.assertGreater(len(sources), 50)
        unformatted = []
        for path in sources:
            formatted = subprocess.run([tool, "--style=file", str(path)], cwd=ROOT, check=True,
                                       capture_output=True).stdout
            if formatted != path.read_bytes():
                unformatted.append(str(path.relative_to(ROOT)))
        self.assertEqual(unformatted, [], "not as .clang-format lays them out (clang-format-16 -i FILE)")


if __name__ == "__main__":
    unittest.main()
