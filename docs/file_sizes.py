#!/usr/bin/env python3
"""Lists the non-test Rust source files over the size limit (900 lines); exit 1 if any.

A file is a test file when it is named `tests.rs`, `*_tests.rs` or `test_support.rs`, or lives
in a `tests/`, `benches/` or `fuzz/` folder. Build output (`target/`) is skipped.

    python3 docs/file_sizes.py [LIMIT]
"""
import os
import sys


def is_test(path):
    name = os.path.basename(path)
    parts = path.split(os.sep)
    return (
        name in ("tests.rs", "test_support.rs")
        or name.endswith("_tests.rs")
        or any(p in ("tests", "benches", "fuzz") for p in parts)
    )


def main():
    limit = int(sys.argv[1]) if len(sys.argv) > 1 else 900
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    over = []
    for base, dirs, files in os.walk(root):
        dirs[:] = [d for d in dirs if d not in ("target", ".git") and not d.startswith("target-")]
        for f in files:
            if not f.endswith(".rs"):
                continue
            path = os.path.relpath(os.path.join(base, f), root)
            if is_test(path):
                continue
            with open(os.path.join(root, path), encoding="utf-8") as h:
                n = sum(1 for _ in h)
            if n > limit:
                over.append((n, path))
    for n, path in sorted(over, reverse=True):
        print(f"{path}: {n} lines (limit {limit})")
    if over:
        return 1
    print(f"no non-test source file over {limit} lines")
    return 0


if __name__ == "__main__":
    sys.exit(main())
