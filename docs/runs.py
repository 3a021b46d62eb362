"""What the measurement scripts of docs/ share: the release binary's path, seed ranges,
and running the CLI (the scripts import it from their own folder)."""

import os
import subprocess

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
# SWEEPHOLD_BINARY names another build (an A/B comparison of two builds).
BINARY = os.environ.get("SWEEPHOLD_BINARY") or os.path.join(ROOT, "target", "release", "sweephold")


def seeds(text):
    """`A-B` (or `A`) as the range of seeds A … B."""
    low, _, high = text.partition("-")
    return range(int(low), int(high or low) + 1)


def run(args, capture=False):
    """Run a command, failing on a non-zero exit; its standard output when `capture`."""
    result = subprocess.run(args, check=True, text=True,
                            stdout=subprocess.PIPE if capture else subprocess.DEVNULL)
    return result.stdout
