//! The little-endian byte reading both log readers share.

/// A little-endian reader over a byte slice that never panics: every read past the end
/// is `None`.
#[derive(Clone, Copy)]
pub(crate) struct Bytes<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Bytes<'a> {
    pub(crate) fn new(data: &'a [u8]) -> Self {
        Bytes { data, pos: 0 }
    }

    pub(crate) fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let end = self.pos.checked_add(n)?;
        let slice = self.data.get(self.pos..end)?;
        self.pos = end;
        Some(slice)
    }

    pub(crate) fn array<const N: usize>(&mut self) -> Option<[u8; N]> {
        self.take(N)?.try_into().ok()
    }

    pub(crate) fn u8(&mut self) -> Option<u8> {
        Some(self.array::<1>()?[0])
    }

    pub(crate) fn u16(&mut self) -> Option<u16> {
        Some(u16::from_le_bytes(self.array()?))
    }

    pub(crate) fn rest(&self) -> &'a [u8] {
        self.data.get(self.pos..).unwrap_or(&[])
    }
}

/// A primitive number type of either format, read little-endian.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Primitive {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Primitive {
    pub(crate) fn size(self) -> usize {
        match self {
            Primitive::I8 | Primitive::U8 => 1,
            Primitive::I16 | Primitive::U16 => 2,
            Primitive::I32 | Primitive::U32 | Primitive::F32 => 4,
            Primitive::I64 | Primitive::U64 | Primitive::F64 => 8,
        }
    }

    /// The value at the start of `b` (`None` when `b` is too short).
    pub(crate) fn read(self, b: &[u8]) -> Option<f64> {
        let mut r = Bytes::new(b);
        Some(match self {
            Primitive::I8 => f64::from(i8::from_le_bytes(r.array()?)),
            Primitive::U8 => f64::from(r.u8()?),
            Primitive::I16 => f64::from(i16::from_le_bytes(r.array()?)),
            Primitive::U16 => f64::from(r.u16()?),
            Primitive::I32 => f64::from(i32::from_le_bytes(r.array()?)),
            Primitive::U32 => f64::from(u32::from_le_bytes(r.array()?)),
            // Exact up to 2⁵³ (time stamps in µs: 285 years).
            Primitive::I64 => i64::from_le_bytes(r.array()?) as f64,
            Primitive::U64 => u64::from_le_bytes(r.array()?) as f64,
            Primitive::F32 => f64::from(f32::from_le_bytes(r.array()?)),
            Primitive::F64 => f64::from_le_bytes(r.array()?),
        })
    }
}

/// Text from NUL-padded bytes: up to the first NUL, invalid UTF-8 replaced.
pub(crate) fn text(bytes: &[u8]) -> String {
    let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    String::from_utf8_lossy(&bytes[..end]).into_owned()
}
