#!/usr/bin/env python3
"""Lists function bodies longer than a limit (default 120 lines) in the project's C++ sources.

A body is a brace block opened at the end of a line that starts at column 0 or, inside a
class, at the first indentation level; lambdas and nested blocks count within their
function. Usage: scripts/long_functions.py [--limit N] [--allow NAME]... [paths...]
Exits 1 when a function not allowed is longer than the limit.
"""
import argparse
import pathlib
import re

FOLDERS = ["geometry", "shading", "scene", "shadermaps", "phases", "controller", "app", "bench"]
SIGNATURE = re.compile(r"^( {0,4})[A-Za-z_~][\w:<>,*&~ \[\]]*\(.*")


def bodies(path):
    lines = path.read_text().split("\n")
    i = 0
    while i < len(lines):
        m = SIGNATURE.match(lines[i])
        if not m or lines[i].rstrip().endswith(";"):
            i += 1
            continue
        # find the opening brace of the body within a few lines of the signature
        j = i
        while j < len(lines) and j < i + 8 and "{" not in lines[j] and not lines[j].rstrip().endswith(";"):
            j += 1
        if j >= len(lines) or "{" not in lines[j]:
            i += 1
            continue
        depth = 0
        k = j
        while k < len(lines):
            depth += lines[k].count("{") - lines[k].count("}")
            if depth <= 0:
                break
            k += 1
        # A GCC attribute before the name (target_clones) is not the name.
        head = re.sub(r"__attribute__\(\(.*?\)\)\s*", "", lines[i])
        name = re.search(r"([\w:~]+)\s*\(", head)
        yield (name.group(1) if name else lines[i].strip()), i + 1, k - i + 1
        i = k + 1


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--limit", type=int, default=120)
    ap.add_argument("--allow", action="append", default=[],
                    help="a function that may be longer (the interpreter's switch, main's table)")
    ap.add_argument("paths", nargs="*")
    args = ap.parse_args()
    root = pathlib.Path(__file__).resolve().parent.parent
    paths = [pathlib.Path(p) for p in args.paths] or [
        p for f in FOLDERS for p in sorted((root / f).rglob("*.cpp"))
    ]
    found = []
    for p in paths:
        for name, line, length in bodies(p):
            if length > args.limit and name not in args.allow:
                found.append((length, f"{p.relative_to(root) if p.is_absolute() else p}:{line}", name))
    for length, where, name in sorted(found, reverse=True):
        print(f"{length:5d}  {where}  {name}")
    return 1 if found else 0


if __name__ == "__main__":
    raise SystemExit(main())
