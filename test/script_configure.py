#!/usr/bin/python3
"""scripts/demo.sh and scripts/test.sh share build/: whichever runs first, the cache must come
out the same, with the tests and the benchmarks on (CTest scripts_configure_alike). Before, a
user who ran the demo first (benchmarks off) never built or tested the benchmarks with
test.sh, which reused that cache; a fresh clone did.

    script_configure.py SOURCE_DIR

Runs each script's configure line (the `cmake -S . -B build ...` of build/, nothing built)
into a fresh folder, in both orders, and compares the options of the resulting caches.
"""
import os
import re
import subprocess
import sys
import tempfile

SRC = os.path.abspath(sys.argv[1])
OPTIONS = ("FACYL_BUILD_TESTS", "FACYL_BUILD_BENCHMARKS", "FACYL_BUILD_APPS",
           "FACYL_BUILD_EXAMPLES", "FACYL_BUILD_PYTHON", "CMAKE_BUILD_TYPE")
failures = []


def configure_line(script):
    """The script's configure command of build/ (its first `cmake -S . -B build ` line)."""
    text = open(os.path.join(SRC, "scripts", script)).read().replace("\\\n", " ")
    for line in text.splitlines():
        line = line.strip()
        if line.startswith("cmake -S . -B build "):
            return re.sub(r"\s*>\s*/dev/null\s*$", "", line)
    raise SystemExit(f"{script}: no 'cmake -S . -B build' line")


def cache(build):
    out = {}
    for line in open(os.path.join(build, "CMakeCache.txt")):
        m = re.match(r"([A-Za-z_0-9]+):[A-Z]+=(.*)", line.strip())
        if m and m.group(1) in OPTIONS:
            out[m.group(1)] = m.group(2)
    return out


results = {}
for order in (("demo.sh", "test.sh"), ("test.sh", "demo.sh")):
    with tempfile.TemporaryDirectory() as tmp:
        build = os.path.join(tmp, "build")
        for script in order:
            cmd = configure_line(script).replace(" -B build ", f" -B {build} ", 1)
            r = subprocess.run(cmd, shell=True, cwd=SRC, capture_output=True, text=True,
                               timeout=600)
            if r.returncode != 0:
                raise SystemExit(f"{script}'s configure failed: {r.stderr[-500:]}")
        results[order] = cache(build)
        print(" then ".join(order) + ": " + str(results[order]))

for order, c in results.items():
    for option in ("FACYL_BUILD_TESTS", "FACYL_BUILD_BENCHMARKS"):
        if c.get(option, "ON").upper() not in ("ON", "TRUE", "1"):
            failures.append(f"{' then '.join(order)}: {option} is {c[option]}")
if len(set(tuple(sorted(c.items())) for c in results.values())) != 1:
    failures.append("the two orders give different caches")
for f in failures:
    print("FAIL " + f)
print(f"{len(failures)} failed" if failures else "all passed")
sys.exit(1 if failures else 0)
