//! The frame link over USART1: telemetry and ActuatorOut frames out, SensorIn frames in.

use sweephold_firmware::FrameSink;
use sweephold_protocol::codec::EncodeError;
use sweephold_protocol::{encode, Decoder, Frame, FrameError, MAX_FRAME_LEN};

use crate::chip::usart::{UsartRx, UsartTx};

/// Bytes taken from the receive ring per decoder pass.
const RX_CHUNK: usize = 64;

/// Scratch space for one encoded frame, kept by the loop so that encoding a frame does
/// not zero a fresh stack buffer every time.
pub type FrameScratch = [u8; MAX_FRAME_LEN];

/// [`FrameSink`] over the transmit ring. Non-blocking: a frame that does not fit is
/// dropped whole and counted ([`UsartTx::dropped_frames`]), so a slow or absent reader
/// never stretches a tick. (The library's `IoSink` over the blocking
/// `embedded_io::Write` of [`UsartTx`] would wait for room instead.) Frames are encoded
/// into the loop's scratch buffer and copied into the ring once.
pub struct Telemetry<'a> {
    tx: &'a mut UsartTx,
    scratch: &'a mut FrameScratch,
}

impl<'a> Telemetry<'a> {
    /// A sink over `tx` for one tick, encoding in `scratch`.
    pub fn new(tx: &'a mut UsartTx, scratch: &'a mut FrameScratch) -> Self {
        Telemetry { tx, scratch }
    }
}

impl FrameSink for Telemetry<'_> {
    fn write_frame(&mut self, bytes: &[u8]) {
        self.tx.queue_frame(bytes);
    }

    fn send_frame(&mut self, frame: &Frame) -> Result<(), EncodeError> {
        // A frame that does not fit is dropped and counted by the ring, as with
        // `write_frame`; encoding itself cannot fail for the protocol's types.
        self.tx.queue_encoded(frame, self.scratch);
        Ok(())
    }
}

/// Encode `frame` (in `scratch`) and queue it ([`UsartTx::queue_encoded`]); `false`
/// when it was dropped (ring full) or could not be encoded (impossible for the
/// protocol's own types with a `MAX_FRAME_LEN` buffer); either is counted as dropped.
pub fn send(tx: &mut UsartTx, scratch: &mut FrameScratch, frame: &Frame) -> bool {
    tx.queue_encoded(frame, scratch)
}

/// Encode `frame` (in `scratch`) and queue it whole, waiting for room in the ring
/// ([`UsartTx::queue_frame_waiting`]) instead of dropping the frame.
pub fn send_waiting(tx: &mut UsartTx, scratch: &mut FrameScratch, frame: &Frame) {
    // Encoded with interrupts enabled; only the copy into the ring masks them.
    if let Ok(len) = encode(frame, scratch) {
        if let Some(bytes) = scratch.get(..len) {
            tx.queue_frame_waiting(bytes);
        }
    }
}

/// Frames arriving from the host.
pub struct Inbound {
    rx: UsartRx,
    decoder: Decoder,
}

impl Inbound {
    /// Decode what arrives on `rx`.
    pub fn new(rx: UsartRx) -> Self {
        Inbound {
            rx,
            decoder: Decoder::new(),
        }
    }

    /// Bytes are waiting to be decoded.
    pub fn has_data(&self) -> bool {
        self.rx.has_data()
    }

    /// Decode every byte received so far, handing each result to `on_frame` in order.
    /// Bounded: at most the receive ring's content.
    pub fn poll(&mut self, mut on_frame: impl FnMut(Result<Frame, FrameError>)) {
        let mut chunk = [0u8; RX_CHUNK];
        loop {
            let count = self.rx.read_available(&mut chunk);
            let Some(bytes) = chunk.get(..count).filter(|bytes| !bytes.is_empty()) else {
                return;
            };
            self.decoder.feed_with(bytes, &mut on_frame);
        }
    }
}
