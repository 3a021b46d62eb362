#!/usr/bin/env bash
# QEMU boot check of the flight-controller image.
#
#   .ci/qemu-boot-check.sh ELF SWEEPHOLD
#
# ELF       the image built by `cargo fw`
#           (target/thumbv7em-none-eabihf/firmware/sweephold-fc)
# SWEEPHOLD the host tool (`cargo build -p sweephold --bin sweephold`)
#
# Builds nothing. Boots ELF in `qemu-system-arm -M netduinoplus2` with USART1 (the first
# -serial) captured to a file, and checks with `SWEEPHOLD decode` that the image sent a
# Header (vehicle and protocol version known) and streamed Samples without tick gaps.
# With no host in the loop the image runs the board application on its own at the control
# rate (disarmed: no IMU under QEMU), so the Samples also measure the tick rate: the
# script snapshots the capture after SETTLE_S and again MEASURE_S later, and reports
# the Samples per second of wall time in between.
#
# Second stage, in the loop (needs python3; LOOP_STEPS=0 skips it): boots the image again
# with USART1 on a unix socket, acts as the host (a small frame encoder/decoder in
# Python, independent of the Rust codec): checks the board application's first frames
# (Header, the IMU reported missing), sends LOOP_STEPS SensorIn frames one at a time,
# flipping the test switch on at the 10th, and checks that each gets exactly one
# ActuatorOut answering its seq with consecutive ticks, that the test sequencer starts
# (Armed, TrimCapture), and that when the host then falls silent the image steps on its
# own and aborts the running test as sensor_stale.
#
# Environment: SETTLE_S (default 1), MEASURE_S (default 3), MIN_RATE_HZ (default 20:
# the loop must tick at least this fast; QEMU's TIM2 model re-arms from the time its
# alarm was served, so a loaded host runs below the nominal 200 Hz), LOOP_STEPS
# (default 400), QEMU (default qemu-system-arm), KEEP_DIR (keep the captures there
# instead of a temporary dir).
set -euo pipefail

fail() {
    echo "qemu-boot-check: FAIL: $*" >&2
    exit 1
}

[[ $# -eq 2 ]] || fail "usage: $0 ELF SWEEPHOLD"
elf=$1
host=$2
settle_s=${SETTLE_S:-1}
measure_s=${MEASURE_S:-3}
min_rate_hz=${MIN_RATE_HZ:-20}
qemu=${QEMU:-qemu-system-arm}

[[ -f $elf ]] || fail "no image at $elf (build it with: cargo fw)"
[[ -x $host ]] || fail "no host tool at $host (build it with: cargo build -p sweephold --bin sweephold)"
command -v "$qemu" >/dev/null || fail "$qemu not found (apt-get install qemu-system-arm)"

if [[ -n ${KEEP_DIR:-} ]]; then
    work=$KEEP_DIR
    mkdir -p "$work"
else
    work=$(mktemp -d)
    trap 'rm -rf "$work"' EXIT
fi
capture=$work/usart1.bin
rm -f "$capture"

# USART1 is the first -serial of netduinoplus2. No monitor, no display; QEMU is killed
# by `timeout` well after the second snapshot in case the kill below is missed.
timeout $((settle_s + measure_s + 10)) "$qemu" -M netduinoplus2 -nographic -monitor none \
    -kernel "$elf" -serial "file:$capture" >"$work/qemu.log" 2>&1 &
qemu_pid=$!

sleep "$settle_s"
cp "$capture" "$work/first.bin" 2>/dev/null || : >"$work/first.bin"
sleep "$measure_s"
cp "$capture" "$work/second.bin" 2>/dev/null || : >"$work/second.bin"
kill "$qemu_pid" 2>/dev/null || true
wait "$qemu_pid" 2>/dev/null || true

# `decode` prints its summary on stderr and exits 0 iff it decoded at least one frame.
summary() {
    "$host" decode "$1" --format jsonl -o /dev/null 2>"$work/summary.txt" \
        || { cat "$work/summary.txt" >&2; fail "no valid frame on USART1 within $2 s (QEMU: $(head -n 1 "$work/qemu.log" | cut -c 1-160))"; }
    cat "$work/summary.txt"
}
first=$(summary "$work/first.bin" "$settle_s")
second=$(summary "$work/second.bin" "$((settle_s + measure_s))")
echo "$second"

grep -q "unknown (no header)" <<<"$second" && fail "frames decoded but no Header among them"
vehicle=$(sed -n 's/.*vehicle \([^,]*\),.*/\1/p' <<<"$second")
protocol=$(sed -n 's/.*protocol \([^,]*\),.*/\1/p' <<<"$second")
rate=$(sed -n 's/.*rate \([0-9]*\) Hz.*/\1/p' <<<"$second")
[[ -n $vehicle && -n $protocol && $protocol != unknown ]] || fail "cannot read vehicle/protocol from the summary"

samples_of() { sed -n 's/.*(\([0-9]*\) samples.*/\1/p' <<<"$1"; }
gaps_of() { sed -n 's/.* \([0-9]*\) tick gaps.*/\1/p' <<<"$1"; }
corrupt_of() { sed -n 's/.* \([0-9]*\) corrupt frames.*/\1/p' <<<"$1"; }
n1=$(samples_of "$first")
n2=$(samples_of "$second")
[[ $n2 -gt 0 ]] || fail "Header but no Sample"
[[ $(gaps_of "$second") -eq 0 ]] || fail "tick gaps in the Sample stream"
# The snapshot may cut the last frame: one truncated frame is expected, more is not.
[[ $(corrupt_of "$second") -le 1 ]] || fail "corrupt frames on USART1"

measured=$(awk -v a="$n1" -v b="$n2" -v t="$measure_s" 'BEGIN { printf "%.1f", (b - a) / t }')
echo "qemu-boot-check: header vehicle $vehicle, protocol $protocol, nominal rate $rate Hz"
echo "qemu-boot-check: $n1 Samples after ${settle_s} s, $n2 after $((settle_s + measure_s)) s: ${measured} ticks/s of wall time"
awk -v m="$measured" -v min="$min_rate_hz" 'BEGIN { exit !(m >= min) }' \
    || fail "tick loop runs at $measured Hz, below MIN_RATE_HZ=$min_rate_hz"

loop_steps=${LOOP_STEPS:-400}
if [[ $loop_steps -eq 0 ]]; then
    echo "qemu-boot-check: in-the-loop stage skipped (LOOP_STEPS=0)"
elif ! command -v python3 >/dev/null; then
    echo "qemu-boot-check: in-the-loop stage skipped (no python3)"
else
    QEMU=$qemu python3 - "$elf" "$loop_steps" "$work" <<'PYTHON' || fail "in-the-loop stage"
"""In-the-loop stage of the QEMU boot check: this script is the host."""
import os, socket, struct, subprocess, sys, time, zlib

PHASES = ["idle", "armed", "trim_capture", "fade_in", "sweep", "fade_out", "done", "aborted"]
ABORT_REASONS = ["attitude_limit", "rate_limit", "sensor_not_finite", "sensor_stale",
                 "pilot_override", "switch_released", "rc_lost", "imu_fault", "disarmed", "landed"]
EVENTS = ["phase_change", "hold_engaged", "hold_released", "trim_captured", "abort",
          "mode_change", "imu_health", "refused", "host_link_ignored", "param_store"]
IMU_HEALTH = ["ok", "calibrating", "missing", "stuck", "saturated", "not_ready", "not_finite",
              "stale"]
FRAME_KINDS = ["header", "sample", "event", "sensor_in", "actuator_out", "configure",
               "configure_result", "param_request", "param_reply", "measurement_filter",
               "servo_test", "servo_test_reply"]


def varint(n):
    """postcard unsigned LEB128."""
    out = bytearray()
    while True:
        low, n = n & 0x7F, n >> 7
        out.append(low | (0x80 if n else 0))
        if not n:
            return bytes(out)


def read_varint(buf, i):
    n = shift = 0
    while True:
        byte = buf[i]
        i += 1
        n |= (byte & 0x7F) << shift
        shift += 7
        if not byte & 0x80:
            return n, i


def cobs_encode(data):
    out = bytearray([0])
    code_at, code = 0, 1
    for byte in data:
        if byte:
            out.append(byte)
            code += 1
        if not byte or code == 0xFF:
            out[code_at] = code
            code_at, code = len(out), 1
            out.append(0)
    out[code_at] = code
    return bytes(out)


def cobs_decode(data):
    out, i = bytearray(), 0
    while i < len(data):
        code = data[i]
        if code == 0:
            raise ValueError("zero byte inside a COBS frame")
        out += data[i + 1:i + code]
        i += code
        if code < 0xFF and i < len(data):
            out.append(0)
    return bytes(out)


def sensor_in(seq, sticks, test_switch):
    """Frame::SensorIn (variant 3): seq, 12 measurements (hover, az = -g), pilot."""
    measurements = [0.0] * 11 + [-9.81]
    payload = (varint(3) + varint(seq) + struct.pack("<12f", *measurements)
               + struct.pack("<4f", *sticks) + bytes([int(test_switch)]))
    return cobs_encode(payload + struct.pack("<I", zlib.crc32(payload))) + b"\0"


def parse(raw):
    """The parts of a frame this check looks at; raises on a bad CRC."""
    body = cobs_decode(raw)
    payload, crc = body[:-4], struct.unpack("<I", body[-4:])[0]
    if zlib.crc32(payload) != crc:
        raise ValueError("CRC mismatch")
    kind, i = read_varint(payload, 0)
    if kind >= len(FRAME_KINDS):
        raise ValueError(f"frame kind {kind} unknown to this check (protocol newer than it)")
    if FRAME_KINDS[kind] == "actuator_out":
        tick, i = read_varint(payload, i)
        seq, i = read_varint(payload, i)
        command = struct.unpack_from("<4f", payload, i)
        i += 16
        servo_us = []
        for _ in range(4):
            pulse, i = read_varint(payload, i)
            servo_us.append(pulse)
        return ("actuator_out", tick, seq, command, servo_us)
    if FRAME_KINDS[kind] == "event":
        variant, i = read_varint(payload, i)
        tick, i = read_varint(payload, i)
        if variant >= len(EVENTS):
            raise ValueError(f"event {variant} unknown to this check (protocol newer than it)")
        if EVENTS[variant] == "phase_change":
            return ("event", "phase_change", tick, PHASES[payload[i]], PHASES[payload[i + 1]])
        if EVENTS[variant] == "abort":
            return ("event", "abort", tick, ABORT_REASONS[payload[i]])
        if EVENTS[variant] == "imu_health":
            return ("event", "imu_health", tick, IMU_HEALTH[payload[i]])
        return ("event", EVENTS[variant], tick)
    return (FRAME_KINDS[kind],)


class Link:
    """USART1 of the emulated board, over QEMU's unix-socket chardev."""

    def __init__(self, path):
        self.sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        for _ in range(200):
            try:
                self.sock.connect(path)
                break
            except OSError:
                time.sleep(0.05)
        else:
            raise SystemExit(f"cannot connect to {path}")
        self.pending = bytearray()

    def frame(self, timeout):
        """The next frame, parsed; None when nothing complete arrives within timeout."""
        self.sock.settimeout(timeout)
        while b"\0" not in self.pending:
            try:
                chunk = self.sock.recv(4096)
            except (socket.timeout, TimeoutError):
                return None
            if not chunk:
                raise SystemExit("the image closed the link")
            self.pending += chunk
        end = self.pending.index(b"\0")
        raw = bytes(self.pending[:end])
        del self.pending[:end + 1]
        return parse(raw) if raw else self.frame(timeout)


def check(elf, steps, workdir):
    say = lambda text: print(f"qemu-boot-check: in the loop: {text}", flush=True)
    socket_path = os.path.join(workdir, "usart1.sock")
    if os.path.exists(socket_path):
        os.unlink(socket_path)
    qemu = subprocess.Popen(
        [os.environ.get("QEMU", "qemu-system-arm"), "-M", "netduinoplus2", "-nographic",
         "-monitor", "none", "-kernel", elf, "-serial", f"unix:{socket_path},server=on,wait=on"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        link = Link(socket_path)
        # The board application: its Header, what its parameter store held (QEMU's
        # flash is blank: the defaults), the IMU reported missing on its first tick
        # (nothing on QEMU's SPI1), then one Sample per tick.
        standalone = [link.frame(5.0) for _ in range(12)]
        kinds = [f[0] if f else None for f in standalone]
        assert kinds[:3] == ["header", "event", "event"] and kinds[3:] == ["sample"] * 9, f"standalone stream: {kinds}"
        assert standalone[1][1] == "param_store", f"first event: {standalone[1]}"
        assert standalone[2][1:] == ("imu_health", 0, "missing"), f"second event: {standalone[2]}"
        say("standalone: Header, parameter store, IMU missing at tick 0, Samples")

        sticks = (0.1, -0.1, 0.05, 0.2)
        first_tick = last_tick = None
        other, events = {}, []
        started = time.monotonic()
        for seq in range(1, steps + 1):
            link.sock.sendall(sensor_in(seq, sticks, test_switch=seq >= 10))
            while True:
                frame = link.frame(5.0)
                assert frame is not None, f"no ActuatorOut for SensorIn {seq} within 5 s"
                if frame[0] == "actuator_out":
                    break
                other[frame[0]] = other.get(frame[0], 0) + 1
                if frame[0] == "event":
                    events.append(frame[1:])
            _, tick, answered, command, servo_us = frame
            assert answered == seq, f"ActuatorOut answers seq {answered}, expected {seq}"
            assert last_tick is None or tick == last_tick + 1, f"tick {tick} after {last_tick}"
            assert all(900 <= pulse <= 2100 for pulse in servo_us), servo_us
            first_tick = tick if first_tick is None else first_tick
            last_tick = tick
        rate = steps / (time.monotonic() - started)
        say(f"{steps} SensorIn -> {steps} ActuatorOut (seq matched), ticks {first_tick}..{last_tick}, "
            f"{rate:.0f} round trips/s; other frames {other}; last command "
            f"{tuple(round(c, 3) for c in command)}, servos {servo_us} us")
        say(f"events {events}")
        assert other.get("header", 0) >= 1, "no Header on entering in-the-loop mode"
        assert ("phase_change", first_tick + 9, "idle", "armed") in [e[:4] for e in events], events

        # The host falls silent: after the link timeout the image steps on its own on the
        # last SensorIn, whose seq no longer changes: the running test aborts as stale.
        silent_samples, silent_events = 0, []
        quiet_from = time.monotonic()
        while time.monotonic() - quiet_from < 2.5:
            frame = link.frame(0.2)
            if frame and frame[0] == "sample":
                silent_samples += 1
            elif frame and frame[0] == "event":
                silent_events.append(frame[1:])
        say(f"host silent 2.5 s: {silent_samples} Samples, events {silent_events}")
        aborts = [e for e in silent_events if e[0] == "abort"]
        assert aborts and aborts[0][2] == "sensor_stale", "no sensor_stale abort after the host fell silent"
    finally:
        qemu.kill()
        qemu.wait()


check(sys.argv[1], int(sys.argv[2]), sys.argv[3])
PYTHON
fi
echo "qemu-boot-check: OK"
