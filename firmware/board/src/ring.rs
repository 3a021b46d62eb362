//! A fixed-size byte ring that moves slices, not bytes.
//!
//! The USART's transmit ring takes a whole frame (~130 bytes) per call and the semihosting
//! link drains it in blocks: copying with at most two block copies per call (the
//! part before the wrap and the part after) costs a word loop instead of a bounds-checked
//! push per byte (heapless `Deque::push_back` in a loop: ~16 instructions a byte).
//! Indices stay in [0, N) and the stored length in [0, N]; every access goes through
//! `get`/`get_mut`, so nothing can panic.
//!
//! The copies themselves are [`copy`]'s word loop, not `copy_from_slice`: a frame lands
//! at whatever offset the ring's tail has, so source and destination are rarely aligned
//! alike, and the library `memcpy` then takes its misaligned path (shifts and merges, a
//! Sample cost ~550 instructions per ring, measured with `docs/board_tick_instructions.py`
//! `TICK_SYMBOLS`); the Cortex-M4 loads and stores words at any address (LDR/STR,
//! unaligned access is not trapped by default), which the loop does: a pilot-mode control
//! tick's copies (its Sample into both rings, the SBUS bytes out of theirs) took 373
//! instructions against the library's 1 177. (No crate for it: the alternative is that `memcpy`,
//! from `compiler_builtins`, which cannot assume unaligned access on every ARM target;
//! `bbqueue`-style grants, encoding straight into the ring, would save one of the two
//! copies but not the other, the log's, and are not done.)

/// Ring of `N` bytes (`N` > 0).
pub struct ByteRing<const N: usize> {
    bytes: [u8; N],
    /// Index of the oldest byte.
    head: usize,
    /// Bytes stored.
    len: usize,
}

impl<const N: usize> ByteRing<N> {
    /// An empty ring.
    pub const fn new() -> Self {
        ByteRing {
            bytes: [0; N],
            head: 0,
            len: 0,
        }
    }

    /// Nothing stored.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Room left.
    pub fn room(&self) -> usize {
        N - self.len
    }

    /// Append as much of `data` as fits; returns how many bytes were taken.
    pub fn push_slice(&mut self, data: &[u8]) -> usize {
        let count = data.len().min(self.room());
        let tail = (self.head + self.len) % N;
        // [tail, N) first, then [0, …) after the wrap.
        let first = count.min(N - tail);
        let (before_wrap, after_wrap) = data.split_at(first.min(data.len()));
        let after_wrap = after_wrap.get(..count - first).unwrap_or(&[]);
        if let Some(slot) = self.bytes.get_mut(tail..tail + first) {
            copy(slot, before_wrap);
        }
        if let Some(slot) = self.bytes.get_mut(..after_wrap.len()) {
            copy(slot, after_wrap);
        }
        self.len += count;
        count
    }

    /// Move the oldest bytes into `out` (at most `out.len()`); returns how many.
    pub fn pop_slice(&mut self, out: &mut [u8]) -> usize {
        let count = out.len().min(self.len);
        let first = count.min(N - self.head);
        let (before_wrap, after_wrap) = out.split_at_mut(first.min(out.len()));
        if let Some(stored) = self.bytes.get(self.head..self.head + first) {
            copy(before_wrap, stored);
        }
        let rest = count - first;
        if let (Some(slot), Some(stored)) = (after_wrap.get_mut(..rest), self.bytes.get(..rest)) {
            copy(slot, stored);
        }
        self.len -= count;
        // An empty ring starts over at 0, so its bytes stay in one piece as long as
        // possible.
        self.head = if self.len == 0 {
            0
        } else {
            (self.head + count) % N
        };
        count
    }

    /// Take the oldest byte. Direct, not through [`pop_slice`](Self::pop_slice): the
    /// transmitters take their bytes one at a time, and a one-byte `memcpy` call per byte
    /// would cost several times the byte's own work.
    pub fn pop(&mut self) -> Option<u8> {
        if self.len == 0 {
            return None;
        }
        let byte = self.bytes.get(self.head).copied();
        self.len -= 1;
        // As in `pop_slice`: an empty ring starts over at 0.
        self.head = if self.len == 0 {
            0
        } else {
            (self.head + 1) % N
        };
        byte
    }

    /// Append one byte; `false` when full. Direct, not through
    /// [`push_slice`](Self::push_slice): the receive interrupts push one byte at a time
    /// (and `docs/board_tick_instructions.py` tells their work from a tick's by symbol).
    pub fn push(&mut self, byte: u8) -> bool {
        if self.len >= N {
            return false;
        }
        let tail = (self.head + self.len) % N;
        match self.bytes.get_mut(tail) {
            Some(slot) => {
                *slot = byte;
                self.len += 1;
                true
            }
            None => false,
        }
    }

    /// Append `frame`, one whole COBS frame ending in its `0x00` delimiter, dropping the
    /// oldest frames (each up to and including its delimiter) until it fits: the ring
    /// then always holds the newest frames. Returns how many frames were dropped: the
    /// oldest ones, or `frame` itself when it is longer than the ring. The oldest frame
    /// may already be partly on the wire: after a drop an extra delimiter goes to the
    /// front of the ring, so such a cut frame ends there (the reader's decoder skips it
    /// as one corrupt frame, and skips the empty frame the delimiter makes otherwise).
    pub fn push_frame_dropping_oldest(&mut self, frame: &[u8]) -> u32 {
        if frame.len() >= N {
            return 1;
        }
        if self.room() >= frame.len() {
            self.push_slice(frame);
            return 0;
        }
        let mut dropped = 0;
        while self.room() < frame.len() + 1 {
            while let Some(byte) = self.pop() {
                if byte == 0 {
                    break;
                }
            }
            dropped += 1;
        }
        self.push_front(0);
        self.push_slice(frame);
        dropped
    }

    /// Put `byte` before the oldest byte (the caller has checked the room).
    fn push_front(&mut self, byte: u8) {
        if self.len < N {
            self.head = (self.head + N - 1) % N;
            if let Some(slot) = self.bytes.get_mut(self.head) {
                *slot = byte;
            }
            self.len += 1;
        }
    }
}

/// Copy `src` into `dst` (the shorter length of the two) a 32-bit word at a time,
/// whatever the alignment of either, then the last bytes. It compiles to one LDR and
/// one STR a word (`llvm-objdump -d`); were the optimiser ever to turn it back into a
/// `memcpy` call, `docs/board_tick_instructions.py`'s `TICK_SYMBOLS` would show it.
fn copy(dst: &mut [u8], src: &[u8]) {
    let len = dst.len().min(src.len());
    let (dst, src) = (
        dst.get_mut(..len).unwrap_or(&mut []),
        src.get(..len).unwrap_or(&[]),
    );
    let mut dst_words = dst.chunks_exact_mut(4);
    let mut src_words = src.chunks_exact(4);
    for (to, from) in (&mut dst_words).zip(&mut src_words) {
        to.copy_from_slice(&word(from).to_ne_bytes());
    }
    for (to, from) in dst_words
        .into_remainder()
        .iter_mut()
        .zip(src_words.remainder())
    {
        *to = *from;
    }
}

/// The four bytes of `bytes` as one word (a single unaligned load on the Cortex-M4).
fn word(bytes: &[u8]) -> u32 {
    match bytes {
        [a, b, c, d] => u32::from_ne_bytes([*a, *b, *c, *d]),
        _ => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::ByteRing;
    use std::collections::VecDeque;

    /// Against `VecDeque` through many wraps with pushes and pops of every size.
    #[test]
    fn behaves_like_a_queue_across_wraps() {
        let mut ring: ByteRing<16> = ByteRing::new();
        let mut model: VecDeque<u8> = VecDeque::new();
        let mut next = 0u8;
        let mut x = 0x9E37_79B9u32;
        for _ in 0..5000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let size = (x % 20) as usize;
            if x & 0x100 != 0 {
                let data: Vec<u8> = (0..size).map(|i| next.wrapping_add(i as u8)).collect();
                let taken = ring.push_slice(&data);
                assert_eq!(taken, size.min(16 - model.len()));
                model.extend(&data[..taken]);
                next = next.wrapping_add(taken as u8);
            } else {
                let mut out = vec![0u8; size];
                let count = ring.pop_slice(&mut out);
                let expected: Vec<u8> = model.drain(..size.min(model.len())).collect();
                assert_eq!(&out[..count], &expected[..]);
            }
            assert_eq!(16 - ring.room(), model.len());
            assert_eq!(ring.is_empty(), model.is_empty());
        }
    }

    /// The onboard log's path: frames as the encoder makes them, through the drop-oldest
    /// ring, drained in bursts as the log UART sends them, and decoded as
    /// `sweephold decode` reads a logger's file.
    #[test]
    fn a_log_drained_like_the_uart_decodes_like_a_dump() {
        use sweephold_protocol::{encode, Axis, Decoder, Event, Frame, SensorIn, MAX_FRAME_LEN};

        let frames: Vec<Frame> = (0..400u32)
            .map(|tick| {
                if tick % 50 == 7 {
                    Frame::Event(Event::HoldEngaged {
                        tick,
                        axis: Axis::Lat,
                    })
                } else {
                    Frame::SensorIn(SensorIn {
                        seq: tick,
                        ..SensorIn::default()
                    })
                }
            })
            .collect();
        let mut ring: ByteRing<1024> = ByteRing::new();
        let mut file = Vec::new();
        let mut dropped = 0;
        let mut scratch = [0u8; MAX_FRAME_LEN];
        for (i, frame) in frames.iter().enumerate() {
            let len = encode(frame, &mut scratch).unwrap();
            dropped += ring.push_frame_dropping_oldest(&scratch[..len]);
            // The logger's line is slower than the loop: it takes fewer bytes per tick
            // than a tick queues, in bursts of varying size, so the ring overflows.
            let mut burst = vec![0u8; 40 + (i * 37) % 60];
            let count = ring.pop_slice(&mut burst);
            file.extend_from_slice(&burst[..count]);
        }
        let mut rest = vec![0u8; 1024];
        let count = ring.pop_slice(&mut rest);
        file.extend_from_slice(&rest[..count]);

        let mut decoder = Decoder::new();
        let results: Vec<_> = decoder.feed(&file).collect();
        let decoded: Vec<Frame> = results
            .iter()
            .filter_map(|r| r.as_ref().ok().copied())
            .collect();
        let corrupt = results.len() - decoded.len();
        assert!(dropped > 0, "the test must overflow the ring");
        // Every frame either arrives intact, in order, or was counted as dropped; a cut
        // frame (dropped while partly sent) is the only kind of corrupt one.
        assert_eq!(decoded.len() + dropped as usize, frames.len());
        assert!(corrupt <= dropped as usize);
        let mut expected = frames.iter();
        for frame in &decoded {
            assert!(expected.any(|f| f == frame), "{frame:?} out of order");
        }
        assert_eq!(decoded.last(), frames.last(), "the newest frames survive");
    }

    #[test]
    fn frames_too_long_for_the_ring_are_dropped_whole() {
        let mut ring: ByteRing<8> = ByteRing::new();
        assert_eq!(ring.push_frame_dropping_oldest(&[1, 2, 3, 0]), 0);
        assert_eq!(ring.push_frame_dropping_oldest(&[4, 5, 0]), 0);
        assert_eq!(ring.push_frame_dropping_oldest(&[1; 9]), 1);
        // Needs 4 bytes and a delimiter, 1 free: the oldest frame goes.
        assert_eq!(ring.push_frame_dropping_oldest(&[6, 7, 8, 0]), 1);
        let mut out = [0u8; 8];
        let count = ring.pop_slice(&mut out);
        assert_eq!(&out[..count], &[0, 4, 5, 0, 6, 7, 8, 0]);
    }

    /// The word copy against `copy_from_slice` at every alignment of either side and
    /// every length up to three pairs of words, and with unequal lengths.
    #[test]
    fn word_copy_copies_every_byte_at_any_alignment() {
        let source: Vec<u8> = (0..64u8)
            .map(|i| i.wrapping_mul(37).wrapping_add(1))
            .collect();
        for src_offset in 0..4 {
            for dst_offset in 0..4 {
                for len in 0..=26 {
                    let mut got = vec![0xAAu8; 40];
                    let mut expected = got.clone();
                    let from = &source[src_offset..src_offset + len];
                    super::copy(&mut got[dst_offset..dst_offset + len], from);
                    expected[dst_offset..dst_offset + len].copy_from_slice(from);
                    assert_eq!(
                        got, expected,
                        "src +{src_offset} dst +{dst_offset} len {len}"
                    );
                }
            }
        }
        let mut short = [0u8; 5];
        super::copy(&mut short, &source[..20]);
        assert_eq!(short, source[..5]);
        let mut long = [0u8; 20];
        super::copy(&mut long, &source[..11]);
        assert_eq!(long[..11], source[..11]);
        assert_eq!(long[11..], [0; 9]);
    }

    #[test]
    fn single_bytes_and_full_ring() {
        let mut ring: ByteRing<3> = ByteRing::new();
        assert!(ring.push(1) && ring.push(2) && ring.push(3));
        assert!(!ring.push(4));
        assert_eq!(ring.room(), 0);
        assert_eq!(ring.pop(), Some(1));
        assert!(ring.push(4));
        assert_eq!(
            [ring.pop(), ring.pop(), ring.pop(), ring.pop()],
            [Some(2), Some(3), Some(4), None]
        );
    }
}
