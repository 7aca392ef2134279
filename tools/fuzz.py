#!/usr/bin/env python3
"""`make fuzz`: the fuzzing campaign of issue 19, for a set time.

Three engines, in two lanes (two cores):
  lane 1  the libFuzzer harnesses (native/fuzz/fuzz_*.cpp: make_scene and a small
          solve, the form-factor kernels with patch_form_factor, visible-polygon
          clipping), built with clang 16 and -fsanitize=fuzzer,address,undefined,
          one after the other, each from its committed seed corpus
          (native/fuzz/corpus/NAME) and what earlier runs added
          (BUILD/fuzz/corpus/NAME), in fork mode so that a crash is saved and
          fuzzing goes on;
  lane 2  atheris (pinned, from PyPI, in BUILD/fuzz/venv) over the Python API
          (native/fuzz/atheris_api.py), then the slice's generators
          (tests/native/fuzz_cases.py) with seeds the slice does not use.
Both Python engines load a `_radiosity` built with clang and
-fsanitize=address,undefined,fuzzer-no-link (BUILD/fuzz/addon/radiosity), with
atheris' ASan runtime preloaded, so libFuzzer sees the C++ coverage and a
memory error in the module is a finding.

At the end: the number of cases each engine ran, the findings grouped by what
they are (sanitizer summary, check that failed, Python exception), with
reproducers (artifact files, seeds). Also written to BUILD/fuzz/report.txt.
Exits 1 if anything was found.

    python3 tools/fuzz.py --build build --seconds 600 [--seed N] [--only libfuzzer,atheris,generator]
"""

import argparse
import base64
import os
import random
import re
import shutil
import subprocess
import sys
import threading
import time
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests" / "native"))
import fuzz_cases  # noqa: E402

ATHERIS = "atheris==3.0.0"
CLANG = "clang-16"
CLANGXX = "clang++-16"
# vptr and function checks need the C++ half of the UBSan runtime, which atheris'
# asan_with_fuzzer.so (the runtime the Python engines preload) does not have.
FLAGS = ("-fsanitize=address,undefined,fuzzer-no-link -fno-sanitize=vptr,function "
         "-fno-sanitize-recover=undefined -fno-omit-frame-pointer")
TARGETS = {"scene": 0.4, "visible_polygon": 0.3, "kernels": 0.3}  # shares of lane 1's time
SAN_ENV = {"ASAN_OPTIONS": "detect_leaks=0:allocator_may_return_null=1:abort_on_error=1",
           "UBSAN_OPTIONS": "print_stacktrace=1:halt_on_error=1"}


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build", help="the project's build directory (this uses BUILD/fuzz)")
    parser.add_argument("--seconds", type=float, default=600, help="wall time of the campaign")
    parser.add_argument("--jobs", type=int, default=2, help="compile jobs")
    parser.add_argument("--seed", type=int, default=None,
                        help="first seed of the generator lane (default: from the clock, printed)")
    parser.add_argument("--only", default="libfuzzer,atheris,generator", help="engines to run")
    parser.add_argument("--python", default="/usr/bin/python3", help="the interpreter the module is built for")
    return parser.parse_args()


def log(text):
    print(text, flush=True)


# --- Build --------------------------------------------------------------------------

def build(args, folder):
    for tool in (CLANG, CLANGXX):
        if not shutil.which(tool):
            raise SystemExit("%s not found: `make fuzz` installs it (bash .ci/install-deps.sh fuzz)" % tool)
    version = subprocess.run([args.python, "-c", "import sys; print('%d.%d' % sys.version_info[:2])"],
                             check=True, capture_output=True, text=True).stdout.strip()
    cmake_dir = folder / "cmake"
    if not (cmake_dir / "CMakeCache.txt").exists():
        env = dict(os.environ, CC=CLANG, CXX=CLANGXX)
        subprocess.run(["cmake", "-S", ROOT, "-B", cmake_dir, "-DCMAKE_BUILD_TYPE=RelWithDebInfo",
                        "-DRADIOSITY_PORTABLE=OFF", "-DRADIOSITY_BUILD_TESTS=OFF",
                        "-DRADIOSITY_BUILD_BENCHMARKS=OFF", "-DRADIOSITY_BUILD_FUZZERS=ON",
                        "-DRADIOSITY_PYTHON_VERSION=%s" % version, "-DCMAKE_CXX_FLAGS=%s" % FLAGS],
                       check=True, env=env, stdout=subprocess.DEVNULL)
    subprocess.run(["cmake", "--build", cmake_dir, "-j", str(args.jobs), "--target",
                    *["fuzz_" + t for t in TARGETS], "_radiosity", "_radiosity_kernels", "addon"], check=True)
    return cmake_dir


def venv(args, folder):
    """BUILD/fuzz/venv: Debian's Python with its numpy, and atheris (pinned)."""
    env_dir = folder / "venv"
    python = env_dir / "bin" / "python"
    if not python.exists():
        subprocess.run([args.python, "-m", "venv", "--system-site-packages", env_dir], check=True)
    if subprocess.run([python, "-c", "import atheris"], capture_output=True).returncode != 0:
        subprocess.run([python, "-m", "pip", "install", "--quiet", ATHERIS], check=True)
    atheris_dir = subprocess.run([python, "-c", "import atheris; print(atheris.path())"], check=True,
                                 capture_output=True, text=True).stdout.strip()
    return python, Path(atheris_dir) / "asan_with_fuzzer.so"


# --- Findings -----------------------------------------------------------------------

def finding_class(text):
    """What a crash log says went wrong, in one line without addresses and numbers."""
    patterns = [r"FUZZ FINDING: [^(\n]*", r"SUMMARY: \w+Sanitizer: [\w-]+ [^\s:]+:\d+",
                r"SUMMARY: \w+Sanitizer: [\w-]+", r"runtime error: [^\n]*",
                r"ERROR: libFuzzer: (timeout|out-of-memory|deadly signal)",
                r"(Finding|\w+Error|\w+Exception): [^\n]*"]
    for pattern in patterns:
        match = re.search(pattern, text)
        if match:
            line = match.group(0)
            line = re.sub(r"0x[0-9a-f]+", "ADDR", line)
            return re.sub(r"-?\b\d[\d.e+-]*\b", "N", line)[:140]
    return "unclassified (exit without a report)"


def classify_artifacts(binary, artifacts, env, limit=40):
    """Reruns saved inputs to read what each one does (the fork mode's log mixes them)."""
    classes = defaultdict(list)
    for path in sorted(artifacts)[:limit]:
        try:
            proc = subprocess.run([binary, str(path)], capture_output=True, text=True, env=env, timeout=120)
            text = proc.stdout + proc.stderr
        except subprocess.TimeoutExpired:
            text = "ERROR: libFuzzer: timeout"
        if path.name.startswith("timeout-"):
            text = "ERROR: libFuzzer: timeout\n" + text
        classes[finding_class(text)].append(path)
    return classes, max(0, len(artifacts) - limit)


# --- Lane 1: libFuzzer --------------------------------------------------------------

def run_libfuzzer(name, binary, seconds, folder, results):
    corpus = folder / "corpus" / name
    corpus.mkdir(parents=True, exist_ok=True)
    artifacts = folder / "artifacts" / name
    artifacts.mkdir(parents=True, exist_ok=True)
    before = set(artifacts.iterdir())
    env = dict(os.environ, **SAN_ENV)
    logfile = folder / ("libfuzzer-%s.log" % name)
    cmd = [str(binary), "-fork=1", "-ignore_crashes=1", "-ignore_timeouts=1", "-ignore_ooms=1",
           "-max_total_time=%d" % max(1, int(seconds)), "-timeout=30", "-rss_limit_mb=4096",
           "-artifact_prefix=%s/" % artifacts, str(corpus), str(ROOT / "native" / "fuzz" / "corpus" / name)]
    start = time.monotonic()
    with open(logfile, "w") as out:
        subprocess.run(cmd, stdout=out, stderr=subprocess.STDOUT, env=env, cwd=folder,
                       timeout=seconds + 300)
    text = logfile.read_text(errors="replace")
    status = re.findall(r"^#(\d+): .*oom/timeout/crash: (\d+)/(\d+)/(\d+)", text, re.MULTILINE)
    runs = int(status[-1][0]) if status else 0
    new = sorted(set(artifacts.iterdir()) - before)
    classes, unread = classify_artifacts(binary, new, env)
    results["libFuzzer " + name] = dict(runs=runs, seconds=time.monotonic() - start, classes=classes,
                                        unread=unread, log=logfile)


# --- Lane 2: atheris and the generators -------------------------------------------------

def run_atheris(python, asan_lib, module_dirs, seconds, folder, results):
    corpus = folder / "corpus" / "atheris"
    corpus.mkdir(parents=True, exist_ok=True)
    artifacts = folder / "artifacts" / "atheris"
    artifacts.mkdir(parents=True, exist_ok=True)
    findings = folder / "atheris-findings.txt"
    findings.unlink(missing_ok=True)
    env = dict(os.environ, LD_PRELOAD=str(asan_lib), FUZZ_FINDINGS_FILE=str(findings), **SAN_ENV)
    deadline = time.monotonic() + seconds
    runs, rounds = 0, 0
    classes = defaultdict(list)
    logfile = folder / "atheris.log"
    with open(logfile, "w") as out:
        # A finding ends an atheris run; the next one goes on from the corpus.
        while time.monotonic() < deadline - 5:
            rounds += 1
            left = int(deadline - time.monotonic())
            cmd = [str(python), str(ROOT / "native" / "fuzz" / "atheris_api.py"),
                   *[option for folder in module_dirs for option in ("--path", str(folder))],
                   "-max_total_time=%d" % left, "-timeout=30", "-rss_limit_mb=4096",
                   "-artifact_prefix=%s/" % artifacts, str(corpus)]
            proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=left + 300)
            text = proc.stdout + proc.stderr
            out.write("=== round %d (exit %d)\n%s\n" % (rounds, proc.returncode, text))
            done = re.findall(r"^Done (\d+) runs", text, re.MULTILINE)
            status = re.findall(r"^#(\d+)\s", text, re.MULTILINE)
            runs += int(done[-1]) if done else (int(status[-1]) if status else 0)
            if proc.returncode != 0:
                saved = re.findall(r"Test unit written to (\S+)", text)
                classes[finding_class(text)].append(saved[-1] if saved else "(round %d of %s)" % (rounds, logfile))
    # Findings in Python, logged by the harness: one saved input per class.
    if findings.exists():
        for line in findings.read_text().splitlines():
            what, _, data = line.partition("\t")
            if not classes[what]:
                path = artifacts / ("finding-%d" % len(classes))
                path.write_bytes(base64.b64decode(data))
                classes[what].append(str(path))
            else:
                classes[what].append("")
    for items in classes.values():
        items.sort(key=lambda item: item == "")
    results["atheris (Python API)"] = dict(runs=runs, seconds=seconds, classes=classes, unread=0, log=logfile)


def run_generators(asan_lib, module_dirs, seconds, first_seed, results):
    env = dict(os.environ, LD_PRELOAD=str(asan_lib), **SAN_ENV)
    campaign = fuzz_cases.Campaign([str(folder) for folder in module_dirs], jobs=1, timeout=120, env=env, python="/usr/bin/python3")
    deadline = time.monotonic() + seconds
    seed = first_seed
    while time.monotonic() < deadline:
        batch = []
        for i in range(200):
            batch += [("scene", seed + i), ("kernel", seed + i)]
        campaign.run(batch, deadline=deadline)
        seed += 200
    classes = defaultdict(list)
    for kind, case_seed, what in campaign.findings:
        key = "%s: %s" % (kind, fuzz_cases.message_class(re.sub(r"^call \d+ ", "", what.splitlines()[0])))
        classes[key].append("%s seed %d" % (kind, case_seed))
    results["generators (seeds %d..)" % first_seed] = dict(
        runs=campaign.cases["scene"] + campaign.calls["kernel"], seconds=campaign.seconds, classes=classes,
        unread=0, detail="%d scenes, %d kernel calls" % (campaign.cases["scene"], campaign.calls["kernel"]),
        errors=campaign.errors)


# --- Main ---------------------------------------------------------------------------

def report(results, path):
    lines = ["Fuzzing campaign (make fuzz)", ""]
    total = 0
    for name, r in results.items():
        total += r["runs"]
        found = sum(len(v) for v in r["classes"].values()) + r["unread"]
        lines.append("%-34s %9d cases %7.0f s %5d findings%s" % (name, r["runs"], r["seconds"], found,
                                                                 "  (%s)" % r["detail"] if "detail" in r else ""))
        for cls, items in sorted(r["classes"].items(), key=lambda kv: -len(kv[1])):
            lines.append("    x%-4d %s" % (len(items), cls))
            for item in [i for i in items if i][:3]:
                lines.append("           e.g. %s" % item)
        if r["unread"]:
            lines.append("    (%d more artifacts not rerun)" % r["unread"])
    lines += ["", "%d cases in all" % total]
    text = "\n".join(lines)
    path.write_text(text + "\n")
    return text


def main():
    args = parse_args()
    folder = (ROOT / args.build / "fuzz") if not os.path.isabs(args.build) else Path(args.build) / "fuzz"
    folder.mkdir(parents=True, exist_ok=True)
    engines = set(args.only.split(","))
    cmake_dir = build(args, folder)
    python, asan_lib = venv(args, folder)
    # _radiosity, and the test-only _radiosity_kernels beside the study's module.
    module_dirs = [cmake_dir / "addon" / "radiosity", cmake_dir / "study"]
    first_seed = args.seed if args.seed is not None else random.SystemRandom().randrange(10 ** 6, 10 ** 9)
    log("make fuzz: %.0f s; generator seeds from %d; logs and artifacts in %s" % (args.seconds, first_seed, folder))
    results = {}

    def lane1():
        shares = {t: s for t, s in TARGETS.items()} if "libfuzzer" in engines else {}
        for name, share in shares.items():
            run_libfuzzer(name, cmake_dir / "fuzzers" / ("fuzz_" + name), args.seconds * share, folder, results)

    def lane2():
        both = "atheris" in engines and "generator" in engines
        if "atheris" in engines:
            run_atheris(python, asan_lib, module_dirs, args.seconds / 2 if both else args.seconds, folder, results)
        if "generator" in engines:
            run_generators(asan_lib, module_dirs, args.seconds / 2 if both else args.seconds, first_seed, results)

    threads = [threading.Thread(target=lane1), threading.Thread(target=lane2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    text = report(results, folder / "report.txt")
    log(text)
    return 1 if any(r["classes"] or r["unread"] for r in results.values()) else 0


if __name__ == "__main__":
    sys.exit(main())
