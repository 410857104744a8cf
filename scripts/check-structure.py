#!/usr/bin/env python3
"""Checks the size limits of the code: no source file of the library, the Python module or the
binary longer than 700 lines, and no function longer than 120 (from its signature to its closing
brace, as Universal Ctags measures it). Prints what exceeds them and exits 1; exits 0 when none
does. Usage: scripts/check-structure.py [--files N] [--functions N]"""
import argparse
import json
import os
import subprocess
import sys

FOLDERS = ["mesh", "integrate", "physics", "cut", "model", "python", "cli", "include"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--files", type=int, default=700, help="most lines of a file")
    parser.add_argument("--functions", type=int, default=120, help="most lines of a function")
    args = parser.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    os.chdir(root)
    sources = subprocess.run(["git", "ls-files", "--", *FOLDERS], capture_output=True, text=True,
                             check=True).stdout.split()
    sources = [f for f in sources if f.endswith((".h", ".cpp")) and os.path.isfile(f)]
    problems = []
    for f in sources:
        with open(f, encoding="utf-8") as text:
            lines = sum(1 for _ in text)
        if lines > args.files:
            problems.append(f"{f}: {lines} lines (at most {args.files}); split it by concept")
    tags = subprocess.run(["ctags", "--languages=C++", "--kinds-C++=f", "--fields=+ne",
                           "--output-format=json", "-o", "-", *sources],
                          capture_output=True, text=True)
    if tags.returncode != 0:
        print("check-structure: ctags failed (apt-get install universal-ctags): " + tags.stderr,
              file=sys.stderr)
        return 2
    for line in tags.stdout.splitlines():
        tag = json.loads(line)
        if "end" not in tag:
            continue
        length = tag["end"] - tag["line"] + 1
        if length > args.functions:
            name = (tag.get("scope", "") + "::" + tag["name"]).lstrip(":")
            problems.append(f"{tag['path']}:{tag['line']}: {name} is {length} lines "
                            f"(at most {args.functions}); split it into named steps")
    for p in problems:
        print(p, file=sys.stderr)
    if problems:
        return 1
    print(f"check-structure: {len(sources)} files within {args.files} lines, "
          f"functions within {args.functions}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
