//! Where encoded telemetry frames go.
//!
//! A [`FrameSink`] receives whole frames (COBS-encoded, delimiter included) from
//! [`FlightController::step`](crate::FlightController::step). Implementations here: a
//! `heapless::Vec<u8, N>` buffer, any embedded-io 0.7 writer through [`IoSink`], a
//! mutable reference to a sink, and, with the `std` feature (or in tests),
//! `std::vec::Vec<u8>`. The host loop implements the trait for its own types.

use sweephold_protocol::codec::EncodeError;
use sweephold_protocol::{encode, Controls, Frame, MAX_FRAME_LEN};

/// Receiver of encoded frames.
pub trait FrameSink {
    /// Take one complete encoded frame. A sink that cannot take it all should drop the
    /// whole frame rather than a part (the decoder resynchronises either way, but a
    /// dropped frame is counted as a tick gap, a torn one as a corrupt frame).
    fn write_frame(&mut self, bytes: &[u8]);

    /// Encode `frame` and take it ([`write_frame`](Self::write_frame)). The default
    /// encodes into a fresh stack buffer; a sink that keeps a scratch buffer of its own
    /// overrides this to encode there and skip zeroing a frame's worth of stack every
    /// time (it is in the per-tick budget of the board).
    fn send_frame(&mut self, frame: &Frame) -> Result<(), EncodeError> {
        let mut buffer = [0u8; MAX_FRAME_LEN];
        let length = encode(frame, &mut buffer)?;
        self.write_frame(buffer.get(..length).unwrap_or(&[]));
        Ok(())
    }

    /// The command a Sample logs for the tick's `command`. The default logs it as it is;
    /// the board application's tap logs what its servo pulses express
    /// ([`crate::mixer::PulseInverse`]): the rotor flies the pulses, not the unrounded
    /// command.
    fn logged_command(&self, command: &Controls) -> Controls {
        *command
    }
}

impl<S: FrameSink + ?Sized> FrameSink for &mut S {
    fn write_frame(&mut self, bytes: &[u8]) {
        (**self).write_frame(bytes);
    }

    fn send_frame(&mut self, frame: &Frame) -> Result<(), EncodeError> {
        (**self).send_frame(frame)
    }

    fn logged_command(&self, command: &Controls) -> Controls {
        (**self).logged_command(command)
    }
}

/// Appends the frame if it fits entirely; drops it otherwise.
impl<const N: usize> FrameSink for heapless::Vec<u8, N> {
    fn write_frame(&mut self, bytes: &[u8]) {
        if self.capacity() - self.len() >= bytes.len() {
            // Cannot fail: the room was checked above.
            let _ = self.extend_from_slice(bytes);
        }
    }
}

/// Appends every frame (host side).
#[cfg(any(test, feature = "std"))]
impl FrameSink for std::vec::Vec<u8> {
    fn write_frame(&mut self, bytes: &[u8]) {
        self.extend_from_slice(bytes);
    }
}

/// Adapts any embedded-io 0.7 [`Write`](embedded_io::Write) (a UART, a ring buffer) to a
/// [`FrameSink`]. Write errors do not stop the control loop: they are counted.
#[derive(Debug)]
pub struct IoSink<W> {
    /// The underlying writer.
    pub writer: W,
    /// Frames whose write failed.
    pub write_errors: u32,
}

impl<W: embedded_io::Write> IoSink<W> {
    /// Wrap `writer`.
    pub const fn new(writer: W) -> Self {
        IoSink {
            writer,
            write_errors: 0,
        }
    }
}

impl<W: embedded_io::Write> FrameSink for IoSink<W> {
    fn write_frame(&mut self, bytes: &[u8]) {
        // Our own `write_all`: embedded-io's default one panics when a writer returns
        // Ok(0). Each pass writes at least one byte, so at most `bytes.len()` passes.
        let mut rest = bytes;
        while !rest.is_empty() {
            match self.writer.write(rest) {
                Ok(written) if written > 0 => rest = rest.get(written..).unwrap_or(&[]),
                _ => {
                    self.write_errors = self.write_errors.saturating_add(1);
                    return;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heapless_vec_keeps_whole_frames_only() {
        let mut buffer: heapless::Vec<u8, 8> = heapless::Vec::new();
        buffer.write_frame(&[1, 2, 3, 0]);
        buffer.write_frame(&[4, 5, 6, 7, 0]);
        buffer.write_frame(&[8, 9, 0]);
        assert_eq!(buffer.as_slice(), &[1, 2, 3, 0, 8, 9, 0]);
    }

    #[test]
    fn io_sink_writes_and_counts_errors() {
        let mut storage = [0u8; 6];
        {
            let mut sink = IoSink::new(&mut storage[..]);
            sink.write_frame(&[1, 2, 0]);
            sink.write_frame(&[3, 4, 5, 0]);
            // The slice writer took the first three bytes of the second frame, then
            // reported Full: one error, and no panic.
            assert_eq!(sink.write_errors, 1);
        }
        assert_eq!(storage, [1, 2, 0, 3, 4, 5]);
    }

    /// A writer that accepts nothing and says so with Ok(0).
    struct Stuck;
    impl embedded_io::ErrorType for Stuck {
        type Error = core::convert::Infallible;
    }
    impl embedded_io::Write for Stuck {
        fn write(&mut self, _buf: &[u8]) -> Result<usize, Self::Error> {
            Ok(0)
        }
        fn flush(&mut self) -> Result<(), Self::Error> {
            Ok(())
        }
    }

    #[test]
    fn io_sink_survives_a_writer_that_writes_nothing() {
        let mut sink = IoSink::new(Stuck);
        sink.write_frame(&[1, 2, 0]);
        assert_eq!(sink.write_errors, 1);
    }

    #[test]
    fn std_vec_and_references_append() {
        let mut bytes = std::vec::Vec::new();
        {
            let by_ref = &mut bytes;
            by_ref.write_frame(&[1, 0]);
        }
        bytes.write_frame(&[2, 0]);
        assert_eq!(bytes, [1, 0, 2, 0]);
    }
}
