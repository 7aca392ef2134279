"""The deterministic fuzz slice of issue 19: generated hostile scenes and kernel
calls through the Python API, each of which must give finite, well-formed output
or a clean ValueError.

2,000 scenes (tests/native/fuzz_cases.py: coincident and duplicated faces,
non-planar n-gons, bow-ties, repeated indices, slivers, near-zero areas, huge
and tiny coordinates, extreme emission, point/spot/sun lights, a world colour,
invalid arguments now and then; random oracle, quality, visibility, threads,
budgets and bounces) and 1,000 batches of 10 kernel calls (form factors, their
gradients, visible form factors exact and sampled, visible polygons, quality
thresholds), with fixed seeds. They run in two worker processes, one case at a
time with a timeout, so a crash or a hang fails the test with its seed instead
of taking the run down. `make fuzz` runs the same generators with other seeds
for longer, and the libFuzzer and atheris harnesses.

FUZZ_SLICE_SCALE=0.1 (environment) runs a tenth of the cases, for a quick look;
the counts printed say what ran.
"""

import os
import pathlib
import sys
import unittest

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import _radiosity as rad  # noqa: E402
from fuzz_cases import Campaign  # noqa: E402
from kernels_module import MISSING, kernels  # noqa: E402

SCALE = float(os.environ.get("FUZZ_SLICE_SCALE", "1"))
SCENES = int(round(2000 * SCALE))
# 10 calls each, of the test-only _radiosity_kernels: none where it is not built.
KERNEL_CASES = int(round(1000 * SCALE)) if kernels is not None else 0
# A case is a small scene solved with at most a few hundred elements: well under a
# second. Sixty seconds is a hang, even on a loaded machine.
TIMEOUT = float(os.environ.get("FUZZ_CASE_TIMEOUT", "60"))


# Findings known and still open, by (kind, seed): reported, not failed on, and
# required to reproduce (when one is fixed, take it off this list).
KNOWN_OPEN = {}


class FuzzSlice(unittest.TestCase):
    def test_generated_cases(self):
        module_dirs = [str(pathlib.Path(module.__file__).resolve().parent) for module in (rad, kernels) if module]
        campaign = Campaign(module_dirs, jobs=2, timeout=TIMEOUT)
        if kernels is None:
            print("[summary] no kernel cases: %s" % MISSING, flush=True)
        # Interleaved, so both kinds run even when a slow machine is watched closely.
        cases = []
        for i in range(max(SCENES, KERNEL_CASES)):
            if i < SCENES:
                cases.append(("scene", i))
            if i < KERNEL_CASES:
                cases.append(("kernel", i))
        campaign.run(cases)
        print(campaign.summary(), flush=True)
        # run_tests.py shows these lines under the file's result.
        for line in campaign.summary().splitlines()[:3]:
            print("[summary] " + line, flush=True)
        self.assertEqual(campaign.cases["scene"], SCENES)
        self.assertEqual(campaign.cases["kernel"], KERNEL_CASES)
        known = [f for f in campaign.findings if f[:2] in KNOWN_OPEN]
        for kind, seed, what in known:
            print("[summary] known, open: %s %d: %s" % (kind, seed, KNOWN_OPEN[(kind, seed)]), flush=True)
        for case in KNOWN_OPEN:
            if case[0] == "scene" and case[1] < SCENES:
                self.assertIn(case, [f[:2] for f in known], "a known finding no longer reproduces: update KNOWN_OPEN")
        new = [f for f in campaign.findings if f[:2] not in KNOWN_OPEN]
        if not new:
            self.assertGreaterEqual(campaign.calls["kernel"], 10 * KERNEL_CASES)
        if new:
            self.fail("\n" + campaign.summary())


if __name__ == "__main__":
    unittest.main()
