#!/usr/bin/env python3
"""Instructions the board image's board application executes per tick, counted under QEMU.

Usage (after `cargo fw --features bench-imu --target-dir target/fw-bench` and
`cargo run -p sweephold-tests --example default_store -- target/default-store.bin`):

    python3 docs/board_tick_instructions.py target/fw-bench/thumbv7em-none-eabihf/firmware/sweephold-fc target/default-store.bin

The second file is the parameter store's sectors holding the defaults, preloaded into the
emulated flash: a board arms only with a valid parameter set stored.

Method: the bench image (its IMU is the flight logic's register-level ICM-42688-P emulator
at rest, since QEMU has nothing on SPI1) runs in `qemu-system-arm -M netduinoplus2` with
`-singlestep -d exec,nochain`: every executed instruction is one "Trace" line with its PC
and symbol, read from a FIFO (as `docs/tick_instructions.py` does for the in-the-loop
step), with `-icount shift=3,sleep=off` so that virtual time, and with it the timer
interrupts, follows the instructions executed, as on a 125 MIPS board, however slowly the
trace runs. This script plays the receiver on the second `-serial` (USART2), paced by the
board's own telemetry on the first (one SBUS frame per two link frames, i.e. every 10 ms
of the board's time): sticks centred and throttle low while the gyro calibrates and
disarmed, then the arm switch on, then throttle at half in the pilot mode. Counted per call, from the first instruction
to the single epilogue `pop {..., pc}`, callees and interrupts included:

* `Runner::control_tick` (200 Hz): the SBUS bytes to the decoder and link monitor, the
  board application's tick (mode logic, pilot-mode loops, sequencer, mixer), its
  telemetry into the link and log rings, the servo and ESC compare registers;
* `Runner::imu_tick` (1 kHz): the IMU poll, monitor, filter bank and estimator.

What the board does not run is counted apart (`NOT_THE_BOARDS`): the emulated chip (its
sampling, and its SPI transaction, which stands in for SPI1's 14-byte exchange) and the
interrupt handlers that land inside a call.

The UARTs' byte pumps are outside the calls by construction, as on the board: a call
only copies its frames into the link and log rings and turns the TXE interrupts on; the
interrupts send the bytes on the board, and under QEMU (whose USART never raises TXE)
the image's loop sends them from thread mode after the timer tick, outside both calls
(`firmware/board/src/chip/usart.rs`). The script checks this: it counts the calls that
stored a byte into a USART's data register (only a full transmit ring makes a waiting
writer do so).

`TICK_SYMBOLS=N` in the environment also lists the N symbols the pilot-mode control
tick's instructions run in, per tick (inlined code counts in its caller; the memory
builtins by their caller), for profiling against `llvm-objdump -d`.

Each is reported by board-application mode as the Samples show it: before arming
(disarmed, calibrated) and in the stabilised pilot mode.

Measured: see docs/performance.md.
"""

import collections
import os
import re
import socket
import statistics
import struct
import subprocess
import sys
import tempfile
import threading

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from tick_instructions import pc_of  # noqa: E402

# SBUS: 16 channels of 11 bits, 172 (low) … 992 (centre) … 1811 (high), the
# flybarless default channel map: 1 lat, 2 lon, 3 throttle, 4 ped, 5 arm, 6 collective,
# 7 test, 8 mode.
LOW, CENTRE, HIGH = 172, 992, 1811


def sbus_frame(arm, throttle):
    channels = [CENTRE] * 16
    channels[2] = int(LOW + throttle * (HIGH - LOW))
    channels[4] = HIGH if arm else LOW
    channels[6] = LOW
    channels[7] = LOW
    bits, acc, data = 0, 0, bytearray()
    for value in channels:
        acc |= (value & 0x7FF) << bits
        bits += 11
        while bits >= 8:
            data.append(acc & 0xFF)
            acc >>= 8
            bits -= 8
    return bytes([0x0F]) + bytes(data) + bytes([0, 0])


def bounds(image, name):
    """Entry and single epilogue of the text symbol whose name contains `name`."""
    symbols = subprocess.run(["llvm-nm", "-S", image], capture_output=True, text=True, check=True)
    for line in symbols.stdout.splitlines():
        fields = line.split()
        if name in line and len(fields) == 4 and fields[2] in "tT" and fields[3].startswith("_ZN"):
            address, size = int(fields[0], 16), int(fields[1], 16)
            break
    else:
        sys.exit(f"no {name} symbol in the image")
    listing = subprocess.run(
        ["llvm-objdump", "-d", f"--start-address={address:#x}", f"--stop-address={address + size:#x}", image],
        capture_output=True, text=True, check=True,
    ).stdout
    exits = [int(l.split(":")[0], 16) for l in listing.splitlines() if re.search(r"\bpop(\.w)?\s.*\bpc\b", l)]
    if len(exits) != 1:
        sys.exit(f"expected one epilogue in {name}, found {len(exits)}")
    return address, exits[0]


# What the board does not run, or runs at its own pace: the emulated chip (its sampling,
# its SPI transaction and the double-precision helpers only it calls: the board's own
# code is single precision) and the interrupt handlers that land inside a call (under a
# full trace QEMU runs far below real time while its timers keep real time, so far more
# of them land than on the board).
NOT_THE_BOARDS = re.compile(
    r"emulator|before_poll|df3|__aeabi_f2d|__aeabi_d2f|__aeabi_d|dcmp|[fF]ixdf|floatun.idf|"
    r"floatsidf|floatdidf|^(TIM5|USART1|USART2|USART3)$|on_interrupt|ByteRing\$LT\$_\$GT\$4push$")


# The UARTs' pumps: inside a call they only turn the TXE interrupt on; a byte sent
# inside one is a store to a data register (USART_DR, offset 4) in them, which happens
# only when a full transmit ring makes a waiting writer feed it (see the module's doc).
PUMPS = re.compile(r"usart4pump|logport4pump")


def data_register_stores(image):
    """Addresses of the pumps' stores to a USART's data register."""
    listing = subprocess.run(["llvm-objdump", "-d", "--no-show-raw-insn", image],
                             capture_output=True, text=True, check=True).stdout
    stores, inside = set(), False
    for line in listing.splitlines():
        if line.endswith(">:"):
            inside = bool(PUMPS.search(line))
        elif inside and re.search(r"\bstrh(\.w)?\s+\w+, \[\w+, #4\]", line):
            stores.add(int(line.split(":")[0], 16))
    if len(stores) != 2:
        sys.exit(f"expected one data-register store in each pump, found {len(stores)}")
    return stores


MEMORY_BUILTINS = re.compile(r"memcpy|memclr|memset|memmove")


def count(log, functions, phase, result, by_symbol, stores):
    """Per call of each function: (phase at entry, instructions, instructions that are
    not the board's, see NOT_THE_BOARDS). The functions do not nest. `by_symbol`, when
    not None, adds up the board's instructions of the pilot-mode control ticks by the
    symbol they execute in (inlined code counts in its caller)."""
    entries = {f"/{entry:08x}/": (name, entry, exit_pc) for name, (entry, exit_pc) in functions.items()}
    active = None
    foreign = {}
    for line in log:
        if not line.startswith("Trace"):
            continue
        if active is None:
            for field, spec in entries.items():
                if field in line and pc_of(line) == spec[1]:
                    active, n, emulated, pumped, started = spec, 0, 0, 0, phase[0]
                    caller = None
                    break
            else:
                continue
        n += 1
        symbol = line[line.rfind(" ") + 1:].rstrip()
        symbol = re.sub(r"17h[0-9a-f]{16}E$", "", symbol) if symbol not in foreign else symbol
        is_foreign = foreign.get(symbol)
        if is_foreign is None:
            is_foreign = foreign[symbol] = bool(NOT_THE_BOARDS.search(symbol))
        if is_foreign:
            emulated += 1
        else:
            if PUMPS.search(symbol) and pc_of(line) in stores:
                pumped += 1
            if by_symbol is not None and started == "pilot" and active[0] == "control_tick":
                # The memory builtins by their caller: which copy or clear it is.
                if MEMORY_BUILTINS.search(symbol):
                    by_symbol[f"{symbol} <- {caller}"] += 1
                else:
                    by_symbol[symbol] += 1
                    caller = symbol
        if f"/{active[2]:08x}/" in line and pc_of(line) == active[2]:
            result.append((active[0], started, n, emulated, pumped))
            active = None


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    image, store = sys.argv[1], sys.argv[2]
    functions = {
        "control_tick": bounds(image, "6Runner12control_tick17h"),
        "imu_tick": bounds(image, "6Runner8imu_tick17h"),
    }
    phase = ["calibrating"]
    result = []
    by_symbol = collections.Counter() if os.environ.get("TICK_SYMBOLS") else None
    with tempfile.TemporaryDirectory() as folder:
        fifo = os.path.join(folder, "exec.log")
        os.mkfifo(fifo)
        servers = []
        for _ in range(2):
            server = socket.socket()
            server.bind(("127.0.0.1", 0))
            server.listen(1)
            servers.append(server)
        link_port, sbus_port = (server.getsockname()[1] for server in servers)
        # -icount: virtual time follows the instructions executed (8 ns each, a 125 MIPS
        # board), so the 1 kHz timer interrupts land as often per instruction as on the
        # board however slowly the trace runs; sleep=off skips the idle time.
        qemu = subprocess.Popen(
            ["taskset", "-c", "0", "qemu-system-arm", "-M", "netduinoplus2", "-nographic",
             "-monitor", "none", "-kernel", image, "-icount", "shift=3,sleep=off",
             "-device", f"loader,file={store},addr=0x080c0000,force-raw=on",
             "-chardev", f"socket,id=link,host=127.0.0.1,port={link_port},server=off",
             "-chardev", f"socket,id=sbus,host=127.0.0.1,port={sbus_port},server=off",
             "-serial", "chardev:link", "-serial", "chardev:sbus",
             "-singlestep", "-d", "exec,nochain", "-D", fifo],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        log = open(fifo, errors="replace")
        reader = threading.Thread(target=count, args=(log, functions, phase, result, by_symbol,
                                                         data_register_stores(image)))
        reader.start()
        link, _ = servers[0].accept()
        sbus, _ = servers[1].accept()
        # The receiver follows the board's own time: one SBUS frame per two frames on
        # the link (a Sample every 5 ms: an SBUS frame every 10 ms).
        frames = 0
        plan = [  # (phase, frames on the link, arm, throttle)
            ("calibrating", int(os.environ.get("CALIBRATION_FRAMES", "260")), False, 0.0),
            ("disarmed", int(os.environ.get("DISARMED_FRAMES", "100")), False, 0.0),
            ("arming", 20, True, 0.0),
            ("pilot", int(os.environ.get("PILOT_FRAMES", "200")), True, 0.5),
        ]
        for name, length, arm, throttle in plan:
            phase[0] = name
            frame = sbus_frame(arm, throttle)
            end = frames + length
            while frames < end:
                data = link.recv(4096)
                if not data:
                    break
                before = frames
                frames += data.count(0)
                for _ in range(frames // 2 - before // 2):
                    sbus.sendall(frame)
        qemu.kill()
        qemu.wait()
        reader.join()
    for name in functions:
        for mode in ("calibrating", "disarmed", "pilot"):
            calls = [(n, e, u) for f, p, n, e, u in result if f == name and p == mode]
            if not calls:
                print(f"{name} ({mode}): no calls traced")
                continue
            totals = sorted(n - e for n, e, _ in calls)
            sent = [u for _, _, u in calls if u > 0]
            emulated = statistics.median(e for _, e, _ in calls)
            print(f"{name} ({mode}): {len(calls)} calls, the board's instructions min {totals[0]} "
                  f"median {statistics.median(totals):.0f} max {totals[-1]} (emulator and "
                  f"interrupts besides: median {emulated:.0f}); calls that sent UART bytes: "
                  f"{len(sent)}" + (f" ({sum(sent)} bytes)" if sent else ""))
    if by_symbol is not None:
        # TICK_SYMBOLS=N: where the pilot-mode control tick's instructions go, per tick.
        ticks = sum(1 for f, p, *_ in result if f == "control_tick" and p == "pilot") or 1
        print(f"control_tick (pilot), instructions per tick by symbol ({ticks} ticks):")
        for name, k in by_symbol.most_common(int(os.environ["TICK_SYMBOLS"])):
            print(f"  {k / ticks:8.1f} {name}")


if __name__ == "__main__":
    main()
