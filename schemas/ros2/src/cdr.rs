//! CDR, as ROS 2 puts it on the wire: a 4-byte encapsulation header (`00 01 00 00`, plain CDR,
//! little-endian), then the fields in order, each primitive aligned to its own size counted from
//! the end of the header. Strings are a `u32` length that counts a closing NUL, the bytes, the
//! NUL; sequences a `u32` count, then the elements; fixed arrays their elements only. Nothing
//! pads the end (rosbags and Fast-CDR agree).
//!
//! [`Reader`] is for untrusted bytes: every length is checked against what is left and against
//! [`Limits`] before anything is allocated, and every failure is a [`CdrError`], never a panic.
//! Big-endian payloads (`00 00`) are read too; [`Writer`] writes little-endian only.

use thiserror::Error;

/// Encapsulation header of a little-endian plain-CDR payload.
pub const CDR_LE_HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];
/// Encapsulation header of a big-endian plain-CDR payload.
pub const CDR_BE_HEADER: [u8; 4] = [0x00, 0x00, 0x00, 0x00];

/// Why bytes were not a message.
#[derive(Debug, Error, Clone, PartialEq, Eq)]
pub enum CdrError {
    /// More bytes than the message type allows, refused before decoding.
    #[error("payload of {len} bytes exceeds the limit of {limit}")]
    TooLarge {
        /// Payload length.
        len: usize,
        /// The type's limit.
        limit: usize,
    },
    /// The first 4 bytes are not a plain-CDR encapsulation header.
    #[error("encapsulation header {0:02x?} is not plain CDR (00 00 or 00 01)")]
    Encapsulation([u8; 4]),
    /// The payload ended inside a field.
    #[error("payload ends inside `{field}`")]
    Truncated {
        /// The field being read.
        field: &'static str,
    },
    /// A sequence or string longer than the limit for its field.
    #[error("`{field}` has {len} elements, more than the limit of {limit}")]
    TooLong {
        /// The field.
        field: &'static str,
        /// Its length on the wire.
        len: u64,
        /// The limit.
        limit: usize,
    },
    /// A string without its closing NUL, with a NUL inside, or not UTF-8.
    #[error("`{field}` is not a NUL-terminated UTF-8 string")]
    BadString {
        /// The field.
        field: &'static str,
    },
    /// Bytes left over after the message (beyond at most 3 zero bytes of padding).
    #[error("{0} bytes left after the message")]
    Trailing(usize),
    /// Decoded, but a value is not finite or not physical.
    #[error("`{field}` is out of bounds: {why}")]
    OutOfBounds {
        /// The field.
        field: &'static str,
        /// What is wrong with it.
        why: &'static str,
    },
}

/// Size limits for decoding one message type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Whole payload, header included.
    pub max_bytes: usize,
    /// Elements of any one sequence.
    pub max_sequence: usize,
    /// Bytes of any one string.
    pub max_string: usize,
}

/// Writes one message: the header, then fields in order.
#[derive(Debug)]
pub struct Writer {
    buf: Vec<u8>,
}

impl Default for Writer {
    fn default() -> Self {
        Self::new()
    }
}

impl Writer {
    /// A writer holding only the little-endian header.
    pub fn new() -> Self {
        let mut buf = Vec::with_capacity(64);
        buf.extend_from_slice(&CDR_LE_HEADER);
        Self { buf }
    }

    /// The finished payload.
    pub fn into_bytes(self) -> Vec<u8> {
        self.buf
    }

    fn align(&mut self, size: usize) {
        let offset = self.buf.len() - CDR_LE_HEADER.len();
        let pad = (size - offset % size) % size;
        self.buf.resize(self.buf.len() + pad, 0);
    }

    /// A `uint8`.
    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }

    /// A `uint32`.
    pub fn u32(&mut self, v: u32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// An `int32`.
    pub fn i32(&mut self, v: i32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `float32`.
    pub fn f32(&mut self, v: f32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `float64`.
    pub fn f64(&mut self, v: f64) {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `string`. A length beyond `u32` cannot be written; the caller's types never hold one.
    pub fn string(&mut self, s: &str) {
        self.len(s.len() + 1);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    /// A sequence's element count.
    pub fn len(&mut self, n: usize) {
        self.u32(u32::try_from(n).unwrap_or(u32::MAX));
    }

    /// A `float32[]`.
    pub fn f32_seq(&mut self, v: &[f32]) {
        self.len(v.len());
        for &x in v {
            self.f32(x);
        }
    }
}

/// Reads one message from untrusted bytes.
#[derive(Debug)]
pub struct Reader<'a> {
    body: &'a [u8],
    pos: usize,
    little_endian: bool,
    limits: Limits,
}

impl<'a> Reader<'a> {
    /// Checks the size limit and the encapsulation header.
    pub fn new(bytes: &'a [u8], limits: Limits) -> Result<Self, CdrError> {
        if bytes.len() > limits.max_bytes {
            return Err(CdrError::TooLarge {
                len: bytes.len(),
                limit: limits.max_bytes,
            });
        }
        let Some((header, body)) = bytes.split_first_chunk::<4>() else {
            return Err(CdrError::Truncated {
                field: "encapsulation header",
            });
        };
        let little_endian = match header[..2] {
            [0x00, 0x01] => true,
            [0x00, 0x00] => false,
            _ => return Err(CdrError::Encapsulation(*header)),
        };
        Ok(Self {
            body,
            pos: 0,
            little_endian,
            limits,
        })
    }

    /// Succeeds when the message used every byte, but for up to 3 zero bytes of padding.
    pub fn finish(self) -> Result<(), CdrError> {
        let rest = &self.body[self.pos..];
        if rest.len() < 4 && rest.iter().all(|&b| b == 0) {
            Ok(())
        } else {
            Err(CdrError::Trailing(rest.len()))
        }
    }

    fn take<const N: usize>(&mut self, field: &'static str) -> Result<[u8; N], CdrError> {
        let pad = (N - self.pos % N) % N;
        let start = self.pos + pad;
        let bytes = self
            .body
            .get(start..start + N)
            .and_then(|s| <[u8; N]>::try_from(s).ok())
            .ok_or(CdrError::Truncated { field })?;
        self.pos = start + N;
        Ok(if self.little_endian {
            bytes
        } else {
            let mut b = bytes;
            b.reverse();
            b
        })
    }

    /// A `uint8`.
    pub fn u8(&mut self, field: &'static str) -> Result<u8, CdrError> {
        Ok(self.take::<1>(field)?[0])
    }

    /// A `uint32`.
    pub fn u32(&mut self, field: &'static str) -> Result<u32, CdrError> {
        Ok(u32::from_le_bytes(self.take(field)?))
    }

    /// An `int32`.
    pub fn i32(&mut self, field: &'static str) -> Result<i32, CdrError> {
        Ok(i32::from_le_bytes(self.take(field)?))
    }

    /// A `float32`.
    pub fn f32(&mut self, field: &'static str) -> Result<f32, CdrError> {
        Ok(f32::from_le_bytes(self.take(field)?))
    }

    /// A `float64`.
    pub fn f64(&mut self, field: &'static str) -> Result<f64, CdrError> {
        Ok(f64::from_le_bytes(self.take(field)?))
    }

    /// A sequence's element count, checked against the limit and against the bytes left (each
    /// element takes at least `min_element_bytes`), so that nothing is allocated for a lie.
    pub fn len(
        &mut self,
        field: &'static str,
        min_element_bytes: usize,
    ) -> Result<usize, CdrError> {
        let n = self.u32(field)? as usize;
        if n > self.limits.max_sequence {
            return Err(CdrError::TooLong {
                field,
                len: n as u64,
                limit: self.limits.max_sequence,
            });
        }
        let left = self.body.len() - self.pos;
        if n.saturating_mul(min_element_bytes.max(1)) > left && min_element_bytes > 0 {
            return Err(CdrError::Truncated { field });
        }
        Ok(n)
    }

    /// A `string`.
    pub fn string(&mut self, field: &'static str) -> Result<String, CdrError> {
        let n = self.u32(field)? as usize;
        if n == 0 {
            return Err(CdrError::BadString { field });
        }
        if n - 1 > self.limits.max_string {
            return Err(CdrError::TooLong {
                field,
                len: n as u64 - 1,
                limit: self.limits.max_string,
            });
        }
        let bytes = self
            .body
            .get(self.pos..self.pos + n)
            .ok_or(CdrError::Truncated { field })?;
        self.pos += n;
        let (text, nul) = bytes.split_at(n - 1);
        if nul != [0] || text.contains(&0) {
            return Err(CdrError::BadString { field });
        }
        String::from_utf8(text.to_vec()).map_err(|_| CdrError::BadString { field })
    }

    /// A `float32[]`.
    pub fn f32_seq(&mut self, field: &'static str) -> Result<Vec<f32>, CdrError> {
        let n = self.len(field, 4)?;
        (0..n).map(|_| self.f32(field)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIMITS: Limits = Limits {
        max_bytes: 1024,
        max_sequence: 8,
        max_string: 16,
    };

    #[test]
    fn primitives_align_to_their_size_after_the_header() {
        let mut w = Writer::new();
        w.u8(7);
        w.f64(1.5);
        w.u8(1);
        w.u32(9);
        let bytes = w.into_bytes();
        // header 4, u8 at 0, pad to 8, f64 at 8..16, u8 at 16, pad to 20, u32 at 20..24.
        assert_eq!(bytes.len(), 4 + 24);
        assert_eq!(&bytes[4 + 8..4 + 16], &1.5f64.to_le_bytes());
        let mut r = Reader::new(&bytes, LIMITS).expect("header");
        assert_eq!(r.u8("a"), Ok(7));
        assert_eq!(r.f64("b"), Ok(1.5));
        assert_eq!(r.u8("c"), Ok(1));
        assert_eq!(r.u32("d"), Ok(9));
        assert_eq!(r.finish(), Ok(()));
    }

    #[test]
    fn big_endian_payloads_read_alike() {
        let mut bytes = CDR_BE_HEADER.to_vec();
        // A u32 zero, then 4 bytes of padding before the f64.
        bytes.extend_from_slice(&[0; 8]);
        bytes.extend_from_slice(&2.25f64.to_be_bytes());
        bytes.extend_from_slice(&3u32.to_be_bytes());
        let mut r = Reader::new(&bytes, LIMITS).expect("header");
        assert_eq!(r.u32("n"), Ok(0));
        assert_eq!(r.f64("x"), Ok(2.25));
        assert_eq!(r.u32("m"), Ok(3));
    }

    #[test]
    fn strings_count_their_nul_and_refuse_without_it() {
        let mut w = Writer::new();
        w.string("map");
        let bytes = w.into_bytes();
        assert_eq!(&bytes[4..], &[4, 0, 0, 0, b'm', b'a', b'p', 0]);
        assert_eq!(
            Reader::new(&bytes, LIMITS).and_then(|mut r| r.string("s")),
            Ok("map".into())
        );
        let mut no_nul = bytes.clone();
        no_nul[11] = b'x';
        assert_eq!(
            Reader::new(&no_nul, LIMITS).and_then(|mut r| r.string("s")),
            Err(CdrError::BadString { field: "s" })
        );
        let zero_len = [0, 1, 0, 0, 0, 0, 0, 0];
        assert!(
            Reader::new(&zero_len, LIMITS)
                .and_then(|mut r| r.string("s"))
                .is_err()
        );
    }

    #[test]
    fn lengths_are_checked_before_allocating() {
        let mut w = Writer::new();
        w.u32(u32::MAX);
        let bytes = w.into_bytes();
        assert!(matches!(
            Reader::new(&bytes, LIMITS).and_then(|mut r| r.f32_seq("ranges")),
            Err(CdrError::TooLong { .. })
        ));
        let mut w = Writer::new();
        w.u32(5);
        w.f32(1.0);
        let bytes = w.into_bytes();
        assert_eq!(
            Reader::new(&bytes, LIMITS).and_then(|mut r| r.f32_seq("ranges")),
            Err(CdrError::Truncated { field: "ranges" })
        );
        let long = Limits {
            max_sequence: 1 << 30,
            ..LIMITS
        };
        let mut w = Writer::new();
        w.u32(1 << 29);
        assert_eq!(
            Reader::new(&w.into_bytes(), long).and_then(|mut r| r.f32_seq("ranges")),
            Err(CdrError::Truncated { field: "ranges" })
        );
    }

    #[test]
    fn headers_sizes_and_trailing_bytes_are_checked() {
        assert_eq!(
            Reader::new(&[0, 1], LIMITS).err(),
            Some(CdrError::Truncated {
                field: "encapsulation header"
            })
        );
        assert!(matches!(
            Reader::new(&[0, 7, 0, 0], LIMITS),
            Err(CdrError::Encapsulation(_))
        ));
        assert!(matches!(
            Reader::new(&[0; 2000], LIMITS),
            Err(CdrError::TooLarge { .. })
        ));
        let padded = [0, 1, 0, 0, 1, 0, 0, 0];
        let mut r = Reader::new(&padded, LIMITS).expect("header");
        assert_eq!(r.u8("b"), Ok(1));
        assert_eq!(r.finish(), Ok(()));
        let extra = [0, 1, 0, 0, 1, 0, 0, 0, 9];
        let mut r = Reader::new(&extra, LIMITS).expect("header");
        assert_eq!(r.u8("b"), Ok(1));
        assert_eq!(r.finish(), Err(CdrError::Trailing(4)));
    }
}
