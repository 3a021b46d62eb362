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
interrupts included (over semihosting the image masks the loop timer's interrupt: the
host is the clock). The run is pinned to one CPU so one QEMU flies every record.

Output: ticks traced; min / median / max instructions per tick; the same without the
framing symbols (encode, COBS, CRC, the queuing and the copies into the link and log
rings); the eight symbols with the most instructions
per tick. TICK_PCS=N in the environment also lists the N most executed instructions
(address and symbol, per tick), for profiling against `llvm-objdump -d`.

Latest figures: docs/performance.md. First measured (2026-11-21, lateral sweep campaign `--t-rec 10 --seed 5`, 6 022 ticks): min 3 123,
median 4 277, max 13 219 (the max is a tick with log lines and events); without framing
median 1 928; lateral doublet (--input doublet --seed 6) median 4 178. Before the f32
sweep phase and the one-pass framing: median 20 651.
"""

import collections
import os
import re
import statistics
import subprocess
import sys
import tempfile
import threading

FRAMING = re.compile(r"codec|queue_frame|queue_encoded|send_waiting|[Ss]erializ|cobs|crc|postcard|usart|logport|ring4copy|ByteRing|board4link")


def step_bounds(image):
    """Entry and epilogue addresses of Runner::step in `image`."""
    symbols = subprocess.run(["llvm-nm", "-S", image], capture_output=True, text=True, check=True)
    for line in symbols.stdout.splitlines():
        fields = line.split()
        # The function itself (a text symbol), not e.g. its `.Lswitch.table` in rodata.
        if "6Runner4step17h" in line and len(fields) == 4 and fields[2] in "tT" and fields[3].startswith("_ZN"):
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
    """Instructions per Runner::step call, in total and outside the framing symbols.

    Tens of millions of trace lines go through here: outside a step only a substring
    test runs per line (the PC field is "/<8 hex digits>/"), and the framing test is
    cached per symbol.
    """
    totals, logic_totals, by_symbol = [], [], collections.Counter()
    by_pc = collections.Counter() if os.environ.get("TICK_PCS") else None
    entry_field, exit_field = f"/{entry:08x}/", f"/{exit_pc:08x}/"
    framing = {}
    inside, n, logic = False, 0, 0
    for line in log:
        if not inside:
            if entry_field not in line or not line.startswith("Trace") or pc_of(line) != entry:
                continue
            inside, n, logic = True, 0, 0
        elif not line.startswith("Trace"):
            continue
        symbol = line[line.rfind(" ") + 1:].rstrip()
        n += 1
        by_symbol[symbol] += 1
        if by_pc is not None:
            by_pc[(pc_of(line), symbol)] += 1
        is_framing = framing.get(symbol)
        if is_framing is None:
            is_framing = framing[symbol] = bool(FRAMING.search(symbol))
        if not is_framing:
            logic += 1
        if exit_field in line and pc_of(line) == exit_pc:
            totals.append(n)
            logic_totals.append(logic)
            inside = False
    result.extend([totals, logic_totals, by_symbol, by_pc])


def pc_of(line):
    """The guest PC of a QEMU "Trace" line: [cs_base/pc/flags/cflags]."""
    try:
        return int(line.split("[", 1)[1].split("/")[1], 16)
    except (IndexError, ValueError):
        return None


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
    totals, logic_totals, by_symbol, by_pc = result
    if not totals:
        sys.exit("no Runner::step call traced")
    print(f"{len(totals)} ticks traced")
    print(summary("instructions per tick (Runner::step)", totals))
    print(summary("  without framing (encode, COBS, CRC, ring)", logic_totals))
    for name, k in by_symbol.most_common(8):
        print(f"  {k / len(totals):8.0f} per tick in {re.sub(r'17h[0-9a-f]{16}E$', '', name)}")
    if by_pc is not None:
        # TICK_PCS=N: the N most executed instructions (address, symbol), per tick.
        for (pc, name), k in by_pc.most_common(int(os.environ["TICK_PCS"])):
            print(f"  {k / len(totals):8.1f} per tick at {pc:#010x} {re.sub(r'17h[0-9a-f]{16}E$', '', name)}")


if __name__ == "__main__":
    main()
