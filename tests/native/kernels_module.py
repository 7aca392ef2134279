"""The test-only module `_radiosity_kernels` (native/kernels: form factors,
visible polygons), which the build makes for its own Python on Linux alone,
beside `_image_metric` in build/study.

`kernels` is the module, or None where it is not built: in the other CPythons
tests/native runs in (run_tests.py --native-python) and under Wine, with the
reason in `MISSING` for the tests that skip there. Where it should be built and
is not, importing this raises ImportError.
"""

import pathlib
import sys

try:
    import _radiosity_kernels as kernels
    MISSING = None
except ImportError:
    kernels = None
    if sys.platform != "linux":
        MISSING = "the test-only _radiosity_kernels is built for Linux alone (native/CMakeLists.txt)"
    else:
        built = sorted(p.name for folder in sys.path for p in pathlib.Path(folder or ".").glob("_radiosity_kernels.*"))
        if not built:
            raise
        MISSING = "the test-only _radiosity_kernels is built for the build's Python alone (%s)" % built[0]
