#!/usr/bin/env python3
"""Lists the non-test Rust source files over their size limit; exit 1 if any.

The limits, by where a file lives (the first matching rule wins):

* `host/` and every other folder not named below: 600 lines;
* `firmware/` and `shared/`: 900 lines (their larger files are split with the firmware's
  regrouping, issue 36, item 5).

A file is a test file when it is named `tests.rs`, `*_tests.rs` or `test_support.rs`, or lives
in a `tests/`, `benches/` or `fuzz/` folder. Build output (`target/`) is skipped.

    python3 docs/file_sizes.py [LIMIT]

With LIMIT, that one limit applies to every file instead.
"""
import os
import sys

# (path prefix, limit): first match wins; the last rule matches every path.
RULES = [
    ("firmware/", 900),
    ("shared/", 900),
    ("", 600),
]


def is_test(path):
    name = os.path.basename(path)
    parts = path.split(os.sep)
    return (
        name in ("tests.rs", "test_support.rs")
        or name.endswith("_tests.rs")
        or any(p in ("tests", "benches", "fuzz") for p in parts)
    )


def limit_of(path, fixed):
    if fixed is not None:
        return fixed
    posix = path.replace(os.sep, "/")
    return next(limit for prefix, limit in RULES if posix.startswith(prefix))


def main():
    fixed = int(sys.argv[1]) if len(sys.argv) > 1 else None
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
            limit = limit_of(path, fixed)
            if n > limit:
                over.append((n, path, limit))
    for n, path, limit in sorted(over, reverse=True):
        print(f"{path}: {n} lines (limit {limit})")
    if over:
        return 1
    if fixed is not None:
        print(f"no non-test source file over {fixed} lines")
    else:
        rules = ", ".join(f"{prefix or 'elsewhere'} {limit}" for prefix, limit in RULES)
        print(f"no non-test source file over its limit ({rules})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
