//! The frame link over ARM semihosting, for QEMU only: `sweephold fly --fc qemu` flies
//! many times faster this way than through QEMU's USART model, which takes one received
//! byte per iteration of QEMU's main loop (~200 lockstep ticks/s). A semihosting call
//! (`BKPT 0xAB`) is served by QEMU's CPU thread at once and moves a whole buffer per
//! call: SYS_READ on a host FIFO gets the SensorIn, SYS_WRITE sends the tick's frames.
//!
//! Selected at run time, never on a board: the image must be in QEMU (the RCC reads back
//! as zeros, [`ClockSource::NoRcc`](crate::chip::clocks::ClockSource::NoRcc), which no STM32F4
//! does) *and* the host must have put the [`MAILBOX`] words into RAM before boot
//! (`-device loader,addr=0x20010000,data=0x53485354,data-len=4` and the complement at
//! 0x20010004). Without `-semihosting` a `BKPT` would be a HardFault, hence the
//! mailbox: the host only writes it when it also enables semihosting. The FIFOs are
//! `sweephold-in` and `sweephold-out` in QEMU's working directory.
//!
//! This module holds `unsafe` code besides `regs`: the semihosting trap (inline
//! assembly) and the mailbox read (a volatile read of a fixed RAM address).

/// RAM address of the mailbox: the middle of SRAM, above the image's static data
/// (~2.4 KiB at the bottom) and far below the main stack (which starts at the top).
pub const MAILBOX: usize = 0x2001_0000;

/// First mailbox word ("SHST"); the second must be its complement.
pub const MAILBOX_MAGIC: u32 = 0x5348_5354;

const SYS_OPEN: u32 = 0x01;
const SYS_WRITE: u32 = 0x05;
const SYS_READ: u32 = 0x06;
const SYS_EXIT: u32 = 0x18;
/// SYS_OPEN modes (fopen's "rb" and "wb").
const MODE_READ_BINARY: u32 = 1;
const MODE_WRITE_BINARY: u32 = 5;
/// SYS_EXIT reason ADP_Stopped_ApplicationExit.
const EXIT_APPLICATION: u32 = 0x2_0026;

/// The host asked for the semihosting link (only meaningful in QEMU: see the module).
pub fn requested() -> bool {
    // SAFETY: MAILBOX and MAILBOX + 4 are word-aligned addresses inside the 128 KiB
    // SRAM, always mapped and readable. No Rust object lives there (static data is at
    // the bottom of SRAM, the stack at the top, and it is only a few KiB deep), so a
    // volatile read aliases nothing; any bit pattern is a valid u32.
    let (word, complement) = unsafe {
        (
            core::ptr::read_volatile(MAILBOX as *const u32),
            core::ptr::read_volatile((MAILBOX + 4) as *const u32),
        )
    };
    word == MAILBOX_MAGIC && complement == !MAILBOX_MAGIC
}

/// One semihosting call: operation `op` with the parameter block `block`.
fn call(op: u32, block: &[usize]) -> isize {
    call_raw(op, block.as_ptr() as usize)
}

/// One semihosting call: operation `op` with `arg` in r1 (a parameter block's address,
/// or for SYS_EXIT on AArch32 the reason itself).
fn call_raw(op: u32, arg: usize) -> isize {
    let result: isize;
    // SAFETY: only reached when `requested()` said QEMU serves semihosting, which then
    // handles `BKPT 0xAB` itself (no exception is taken). The calls used here read the
    // parameter block and the buffers it points to (borrowed by the caller for the
    // duration of the call, so alive) and write only into buffers the caller holds as
    // `&mut`; r0 returns the result.
    unsafe {
        core::arch::asm!(
            "bkpt #0xAB",
            inout("r0") op as usize => result,
            in("r1") arg,
            options(nostack)
        );
    }
    result
}

/// Open a host file; `path` ends with a NUL. `None` when the host refuses.
pub fn open(path: &[u8], write: bool) -> Option<usize> {
    let mode = if write {
        MODE_WRITE_BINARY
    } else {
        MODE_READ_BINARY
    };
    let len = path.len().saturating_sub(1);
    let handle = call(SYS_OPEN, &[path.as_ptr() as usize, mode as usize, len]);
    usize::try_from(handle).ok()
}

/// Read at least one byte into `buf` (blocks until there is one); 0 at end of file or
/// on an error.
pub fn read(handle: usize, buf: &mut [u8]) -> usize {
    // SYS_READ returns the number of bytes *not* read.
    let left = call(SYS_READ, &[handle, buf.as_mut_ptr() as usize, buf.len()]);
    usize::try_from(left).map_or(0, |left| buf.len().saturating_sub(left))
}

/// Write all of `bytes`; `false` on an error.
pub fn write(handle: usize, bytes: &[u8]) -> bool {
    call(SYS_WRITE, &[handle, bytes.as_ptr() as usize, bytes.len()]) == 0
}

/// Ask QEMU to exit (the host is gone).
pub fn exit() -> ! {
    call_raw(SYS_EXIT, EXIT_APPLICATION as usize);
    loop {
        cortex_m::asm::wfi();
    }
}
