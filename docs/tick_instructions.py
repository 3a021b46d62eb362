#!/usr/bin/env python3
"""Instructions the board image executes per tick, counted under QEMU.

Usage (after `cargo fw` and `cargo build -p sweephold`):

    python3 docs/tick_instructions.py IMAGE SWEEPHOLD [fly arguments...]
    python3 docs/tick_instructions.py target/thumbv7em-none-eabihf/firmware/sweephold-fc \
        target/debug/sweephold --axes lat --t-rec 10 --seed 5

Method: the image is not changed. `sweephold fly --fc qemu` runs it with
`-singlestep -d exec,nochain` added to QEMU's command line (SWEEPHOLD_QEMU_ARGS): every
translation block is then one instruction and QEMU logs each execution of one ("Trace"
lines, with the PC and its symbol) to a FIFO this script reads. An instruction count per
call of `Runner::step` (the flight logic, the encoding of its Sample/Events and the
ActuatorOut into the transmit ring, the servo update) runs from the function's first
instruction to its single epilogue `pop {..., pc}` (found with llvm-objdump; `on_frame`
reaches the function by a tail call, so the return address is not usable), callees and
interrupts included. The run is pinned to one CPU so one QEMU flies every record.
"""

import collections
import os
import re
import statistics
import subprocess
import sys
import tempfile
import threading

FRAMING = re.compile(r"codec|queue_frame|send_waiting|[Ss]erializ|cobs|crc|postcard|usart|board4link")


def step_bounds(image):
    """Entry and epilogue addresses of Runner::step in `image`."""
    symbols = subprocess.run(["llvm-nm", "-S", image], capture_output=True, text=True, check=True)
    for line in symbols.stdout.splitlines():
        if "6Runner4step17h" in line:
            address, size = int(line.split()[0], 16), int(line.split()[1], 16)
            break
    else:
        sys.exit("no Runner::step symbol in the image")
    listing = subprocess.run(
        ["llvm-objdump", "-d", f"--start-address={address:#x}", f"--stop-address={address + size:#x}", image],
        capture_output=True, text=True, check=True,
    ).stdout
    exits = [int(l.split(":")[0], 16) for l in listing.splitlines() if re.search(r"\bpop(\.w)?\s.*\bpc\b", l)]
    if len(exits) != 1:
        sys.exit(f"expected one epilogue in Runner::step, found {len(exits)}")
    return address, exits[0]


def count(log, entry, exit_pc, result):
    totals, logic_totals, by_symbol = [], [], collections.Counter()
    inside, n, logic = False, 0, 0
    for line in log:
        if not line.startswith("Trace"):
            continue
        try:
            pc = int(line.split("[", 1)[1].split("/")[1], 16)
        except (IndexError, ValueError):
            continue
        if not inside and pc != entry:
            continue
        if not inside:
            inside, n, logic = True, 0, 0
        symbol = line.rsplit(" ", 1)[-1].strip()
        n += 1
        by_symbol[symbol] += 1
        logic += 0 if FRAMING.search(symbol) else 1
        if pc == exit_pc:
            totals.append(n)
            logic_totals.append(logic)
            inside = False
    result.extend([totals, logic_totals, by_symbol])


def summary(name, values):
    values = sorted(values)
    return f"{name}: min {values[0]} median {statistics.median(values):.0f} max {values[-1]}"


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    image, sweephold, fly_args = sys.argv[1], sys.argv[2], sys.argv[3:]
    entry, exit_pc = step_bounds(image)
    with tempfile.TemporaryDirectory() as folder:
        fifo = os.path.join(folder, "exec.log")
        os.mkfifo(fifo)
        env = dict(os.environ, SWEEPHOLD_QEMU_ARGS=f"-singlestep -d exec,nochain -D {fifo}")
        command = ["taskset", "-c", "0", sweephold, "fly", "--fc", "qemu", "--elf", image, "-q",
                   "--out", os.path.join(folder, "out"), *fly_args]
        flight = subprocess.Popen(command, env=env)
        result = []
        with open(fifo, errors="replace") as log:
            reader = threading.Thread(target=count, args=(log, entry, exit_pc, result))
            reader.start()
            status = flight.wait()
            reader.join()
    if status != 0:
        sys.exit(f"sweephold fly failed ({status})")
    totals, logic_totals, by_symbol = result
    if not totals:
        sys.exit("no Runner::step call traced")
    print(f"{len(totals)} ticks traced")
    print(summary("instructions per tick (Runner::step)", totals))
    print(summary("  without framing (encode, COBS, CRC, ring)", logic_totals))
    for name, k in by_symbol.most_common(8):
        print(f"  {k / len(totals):8.0f} per tick in {re.sub(r'17h[0-9a-f]{16}E$', '', name)}")


if __name__ == "__main__":
    main()
