"""A virtual environment of a given interpreter with pinned requirements from PyPI,
made once and reused (tools/blenders.py's bpys, tests/run_tests.py's Pythons).

An environment is ready when its stamp (FOLDER/installed.txt) names the same
interpreter and requirements; otherwise make() replaces it. Wheels only
(`--only-binary :all:`): nothing is compiled here.
"""

import shutil
import subprocess
import time
from pathlib import Path

STAMP = "installed.txt"


def python(folder):
    return Path(folder) / "bin" / "python"


def _stamp_text(base_python, requirements):
    return "%s\npython %s\n" % (" ".join(requirements), base_python)


def ready(folder, base_python, requirements):
    stamp = Path(folder) / STAMP
    return stamp.exists() and stamp.read_text() == _stamp_text(base_python, requirements)


def make(folder, base_python, requirements, log=print):
    """Make FOLDER an environment of BASE_PYTHON with REQUIREMENTS; a no-op when ready."""
    folder = Path(folder)
    if ready(folder, base_python, requirements):
        return False
    log("Installing %s into %s (Python %s)" % (" ".join(requirements), folder, base_python))
    start = time.perf_counter()
    if folder.exists():
        shutil.rmtree(folder)
    subprocess.run([str(base_python), "-m", "venv", str(folder)], check=True)
    subprocess.run([str(python(folder)), "-m", "pip", "--disable-pip-version-check", "install", "--quiet",
                    "--only-binary", ":all:", *requirements], check=True)
    (folder / STAMP).write_text(_stamp_text(base_python, requirements))
    log("Installed %s in %.0f s" % (folder.name, time.perf_counter() - start))
    return True
