#!/usr/bin/env python3
"""The mutation campaign: plants each mutant of scripts/mutants.txt in turn, rebuilds
build/ incrementally, runs the test suite, and reports which mutants survive.

    scripts/mutate.py [--only SUBSTRING] [--list FILE]

A mutant is killed when the build fails or any test fails. The working tree is restored
after each mutant (and on Ctrl-C). Needs build/ configured (scripts/setup.sh build).
Prints one line per mutant and the score; exit status 0 always (a report, not a gate).
"""
import argparse
import pathlib
import subprocess
import sys
import time

root = pathlib.Path(__file__).resolve().parent.parent


def load(path):
    mutants = []
    for number, line in enumerate(path.read_text().splitlines(), 1):
        if not line.strip() or line.startswith("#"):
            continue
        parts = [p.strip() for p in line.split(" | ")]
        if len(parts) != 4:
            sys.exit(f"{path}:{number}: expected FILE | ORIGINAL | MUTANT | WHY")
        mutants.append((number, *parts))
    return mutants


def run(cmd, timeout):
    try:
        return subprocess.run(cmd, cwd=root, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL, timeout=timeout).returncode
    except subprocess.TimeoutExpired:
        return -1  # a hang counts as killed


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--only", default="")
    parser.add_argument("--list", default=str(root / "scripts" / "mutants.txt"))
    args = parser.parse_args()
    mutants = [m for m in load(pathlib.Path(args.list)) if args.only in m[1] + m[4]]
    killed, survivors, start = 0, [], time.time()
    for number, file, original, mutant, why in mutants:
        path = root / file
        text = path.read_text()
        if text.count(original) != 1:
            print(f"line {number}: {file}: the original occurs {text.count(original)} times; skipped")
            continue
        try:
            path.write_text(text.replace(original, mutant))
            t0 = time.time()
            built = run(["cmake", "--build", "build", "--target", "mpshade", "mpshade_tests",
                         "mpshade_cli_tests"], 1200) == 0
            passed = built and run(["ctest", "--test-dir", "build", "-j2", "--timeout", "300"],
                                   1800) == 0
        finally:
            path.write_text(text)
        verdict = "survived" if passed else ("killed (build)" if not built else "killed")
        if passed:
            survivors.append(f"{file}: {why}")
        else:
            killed += 1
        print(f"{verdict:15} {time.time() - t0:6.0f} s  {file}: {why}", flush=True)
    total = len(mutants)
    print(f"score: {killed}/{total} killed ({100.0 * killed / max(total, 1):.0f}%), "
          f"{time.time() - start:.0f} s")
    for s in survivors:
        print("survivor:", s)
    # Rebuild the restored tree so build/ matches the sources again.
    run(["cmake", "--build", "build"], 1200)


if __name__ == "__main__":
    main()
