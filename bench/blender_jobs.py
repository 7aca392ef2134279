"""Runs the study's Blender-side scripts (blender_export.py, blender_render.py,
blender_bake.py) in headless Blender, one process per call, and fails loudly
with Blender's log when one does not finish."""

import json
import pathlib
import subprocess
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
TAG = "[study] "


class BlenderError(RuntimeError):
    pass


def run(blender, blend, script, args, verbose=False):
    """Run HERE/script on `blend` with `args` after `--`; returns the tagged lines."""
    cmd = [blender, "--background", "--factory-startup", str(blend), "--python-exit-code", "1",
           "--python", str(HERE / script), "--"] + [str(a) for a in args]
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, stdin=subprocess.DEVNULL)
    log = proc.stdout + proc.stderr
    lines = [line[len(TAG):] for line in log.splitlines() if line.startswith(TAG)]
    if verbose:
        for line in lines:
            print("    " + line, flush=True)
    if proc.returncode != 0:
        raise BlenderError("%s on %s failed (exit %d) after %.0f s:\n%s"
                           % (script, blend, proc.returncode, time.perf_counter() - start, log[-4000:]))
    return lines


def run_with_jobs(blender, blend, script, addon, jobs, jobs_path, verbose=False):
    """Write `jobs` to jobs_path and run `script` with --addon and --jobs."""
    pathlib.Path(jobs_path).write_text(json.dumps(jobs, indent=1))
    return run(blender, blend, script, ["--addon", addon, "--jobs", jobs_path], verbose)


def export(blender, blend, addon, out, verbose=False):
    return run(blender, blend, "blender_export.py", ["--addon", addon, "--out", out], verbose)


if __name__ == "__main__":
    sys.exit("used by bench/study.py")
