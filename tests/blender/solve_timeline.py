"""A bundled scene solved as a user solves it, for tests/blender/test_interactive.py
and bench/window_speed.py: headless on a worker thread, through the pipeline the
window's operator runs, and in a real window on a virtual X display
(interactive_solve.py, which presses Esc with xdotool)."""

import json
import os
import subprocess
import threading
import time

import bpy

from radiosity.solve import native, pipeline
from test_solve import ADDON_DIR, build_file, open_scene

HERE = os.path.dirname(os.path.abspath(__file__))


def headless_timeline(name, quality, marks=(), stop=None):
    """A headless solve of scene `name` at `quality` on a worker thread (a
    ProgressMonitor polled every 5 ms, as the window polls it): returns
    {pass: (seconds after the start when it completed, its leaves)} and
    {mark: leaves refined by then} for each mark in seconds. Cancelled once
    stop(completed, seconds) says so after a completed pass, to spare the rest."""
    open_scene(name).radiosity.quality = quality
    solver = native.load()
    started = time.perf_counter()
    job = pipeline.prepare(bpy.context, solver, started)
    job.monitor = solver.ProgressMonitor()
    token = solver.CancelToken()
    worker = threading.Thread(target=pipeline.work, args=(solver, job, token))
    worker.start()
    completed, leaves_after = {}, {}
    while worker.is_alive():
        progress, now = job.monitor.progress(), time.perf_counter() - started
        if progress:
            for mark in marks:
                if now >= mark and mark not in leaves_after:
                    leaves_after[mark] = progress.get("leaves", 0)
            if progress.get("phase") == "pass" and progress["pass"] not in completed:
                completed[progress["pass"]] = (now, progress["leaves"])
                if stop is not None and stop(completed, now):
                    token.cancel()
        time.sleep(0.005)
    worker.join()
    return completed, leaves_after


def run_window(scene, mode, shots=None):
    """Scene `scene` solved in a Blender window (interactive_solve.py's `mode`:
    run, cancel, cancel_after:SECONDS): its RESULT record, or AssertionError
    with the window's output."""
    cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", bpy.app.binary_path, "--factory-startup",
           build_file(scene), "--python",
           os.path.join(HERE, "interactive_solve.py"), "--", ADDON_DIR, mode] + ([shots] if shots else [])
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300, stdin=subprocess.DEVNULL)
    lines = [line for line in proc.stdout.splitlines() if line.startswith("RESULT ")]
    if not lines:
        raise AssertionError(proc.stdout[-3000:] + proc.stderr[-3000:])
    return json.loads(lines[-1][len("RESULT "):])
