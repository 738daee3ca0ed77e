//! The few pieces of the protocol-buffer wire format that TensorBoard's messages need:
//! writing fields into a message, and walking the fields of one. A whole protobuf crate
//! with generated code would be larger than the handful of messages it would serve.
//!
//! A message is a sequence of fields, each a key (`field number << 3 | wire type`, a
//! varint) and a payload: a varint (wire type 0), 8 bytes little-endian (1), a
//! length-prefixed run of bytes (2: strings, bytes, nested messages, packed repeated
//! numbers) or 4 bytes little-endian (5).

/// A message being written, field by field, in the order the calls come.
///
/// Every call writes its field, a default value included: proto3 leaves out fields equal
/// to their default only where presence does not matter, and a field inside a `oneof`
/// (a `simple_value` of 0.0, a `bool_value` of false) must be written. Callers skip
/// the plain defaults themselves.
#[derive(Debug, Default, Clone)]
pub struct Message {
    bytes: Vec<u8>,
}

impl Message {
    pub fn new() -> Self {
        Self::default()
    }

    /// A `double` (wire type 1).
    pub fn double(mut self, field: u32, value: f64) -> Self {
        self.key(field, 1);
        self.bytes.extend_from_slice(&value.to_le_bytes());
        self
    }

    /// A `float` (wire type 5).
    pub fn float(mut self, field: u32, value: f32) -> Self {
        self.key(field, 5);
        self.bytes.extend_from_slice(&value.to_le_bytes());
        self
    }

    /// An `int64`, or an `int32` or enum widened to it: a negative number is its 64-bit
    /// two's complement, as protobuf writes both.
    pub fn int64(mut self, field: u32, value: i64) -> Self {
        self.key(field, 0);
        self.varint(value as u64);
        self
    }

    /// A `bool`.
    pub fn bool(self, field: u32, value: bool) -> Self {
        self.int64(field, i64::from(value))
    }

    /// A `string`.
    pub fn string(self, field: u32, value: &str) -> Self {
        self.bytes_field(field, value.as_bytes())
    }

    /// A `bytes` field.
    pub fn bytes_field(mut self, field: u32, value: &[u8]) -> Self {
        self.key(field, 2);
        self.varint(value.len() as u64);
        self.bytes.extend_from_slice(value);
        self
    }

    /// A nested message.
    pub fn message(self, field: u32, value: &Message) -> Self {
        self.bytes_field(field, &value.bytes)
    }

    /// The encoded message.
    pub fn into_bytes(self) -> Vec<u8> {
        self.bytes
    }

    fn key(&mut self, field: u32, wire_type: u8) {
        self.varint(u64::from(field) << 3 | u64::from(wire_type));
    }

    fn varint(&mut self, mut value: u64) {
        while value >= 0x80 {
            self.bytes.push(value as u8 | 0x80);
            value >>= 7;
        }
        self.bytes.push(value as u8);
    }
}

/// A field's payload, by wire type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Payload<'a> {
    Varint(u64),
    Fixed64([u8; 8]),
    Fixed32([u8; 4]),
    Bytes(&'a [u8]),
}

impl<'a> Payload<'a> {
    /// The payload as a `double`, if it is 8 bytes.
    pub fn as_f64(self) -> Option<f64> {
        match self {
            Payload::Fixed64(b) => Some(f64::from_le_bytes(b)),
            _ => None,
        }
    }

    /// The payload as a `float`, if it is 4 bytes.
    pub fn as_f32(self) -> Option<f32> {
        match self {
            Payload::Fixed32(b) => Some(f32::from_le_bytes(b)),
            _ => None,
        }
    }

    /// The payload as an `int64` (or a narrower integer or enum), if it is a varint.
    pub fn as_i64(self) -> Option<i64> {
        match self {
            Payload::Varint(v) => Some(v as i64),
            _ => None,
        }
    }

    /// The payload's bytes, if it is length-delimited.
    pub fn as_bytes(self) -> Option<&'a [u8]> {
        match self {
            Payload::Bytes(b) => Some(b),
            _ => None,
        }
    }
}

/// Why a message could not be walked: its bytes end inside a field, or a field uses the
/// long-deprecated group wire types (3, 4) or none at all.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum DecodeError {
    #[error("a protobuf field runs past the end of its message")]
    Truncated,
    #[error("a protobuf varint is longer than 10 bytes")]
    LongVarint,
    #[error("a protobuf field has wire type {0}, which no TensorBoard message uses")]
    WireType(u8),
    #[error("a protobuf field of the wrong wire type for its number")]
    WrongType,
    #[error("a protobuf string is not UTF-8")]
    NotUtf8,
}

/// The fields of an encoded message, in order: `(field number, payload)`. Nested messages
/// are `Payload::Bytes`, walked with another `Fields` if the reader cares for them.
#[derive(Debug, Clone)]
pub struct Fields<'a> {
    rest: &'a [u8],
}

impl<'a> Fields<'a> {
    pub fn new(message: &'a [u8]) -> Self {
        Self { rest: message }
    }

    fn field(&mut self) -> Result<(u32, Payload<'a>), DecodeError> {
        let key = self.varint()?;
        let wire_type = (key & 7) as u8;
        let field = (key >> 3) as u32;
        let payload = match wire_type {
            0 => Payload::Varint(self.varint()?),
            1 => Payload::Fixed64(self.take(8)?.try_into().expect("8 bytes")),
            2 => {
                let len = self.varint()?;
                let len = usize::try_from(len).map_err(|_| DecodeError::Truncated)?;
                Payload::Bytes(self.take(len)?)
            }
            5 => Payload::Fixed32(self.take(4)?.try_into().expect("4 bytes")),
            other => return Err(DecodeError::WireType(other)),
        };
        Ok((field, payload))
    }

    fn varint(&mut self) -> Result<u64, DecodeError> {
        let mut value = 0u64;
        for (i, &byte) in self.rest.iter().enumerate().take(10) {
            value |= u64::from(byte & 0x7f) << (7 * i);
            if byte & 0x80 == 0 {
                self.rest = &self.rest[i + 1..];
                return Ok(value);
            }
        }
        Err(if self.rest.len() < 10 {
            DecodeError::Truncated
        } else {
            DecodeError::LongVarint
        })
    }

    fn take(&mut self, len: usize) -> Result<&'a [u8], DecodeError> {
        if len > self.rest.len() {
            return Err(DecodeError::Truncated);
        }
        let (taken, rest) = self.rest.split_at(len);
        self.rest = rest;
        Ok(taken)
    }
}

impl<'a> Iterator for Fields<'a> {
    type Item = Result<(u32, Payload<'a>), DecodeError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.rest.is_empty() {
            return None;
        }
        let field = self.field();
        if field.is_err() {
            // One error ends the walk: what follows a broken field cannot be framed.
            self.rest = &[];
        }
        Some(field)
    }
}

/// A length-delimited payload as UTF-8 text.
pub fn text(bytes: &[u8]) -> Result<&str, DecodeError> {
    std::str::from_utf8(bytes).map_err(|_| DecodeError::NotUtf8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_written_as_the_protobuf_encoding_guide_shows() {
        // protobuf.dev's encoding guide: field 1 = 150 is 08 96 01; field 2 = "testing"
        // is 12 07 74 65 73 74 69 6e 67.
        assert_eq!(
            Message::new().int64(1, 150).into_bytes(),
            [0x08, 0x96, 0x01]
        );
        assert_eq!(
            Message::new().string(2, "testing").into_bytes(),
            b"\x12\x07testing"
        );
        // A negative int64 takes ten bytes: its 64-bit two's complement.
        let minus_one = Message::new().int64(2, -1).into_bytes();
        assert_eq!(minus_one.len(), 11);
        assert_eq!(minus_one[1..10], [0xff; 9]);
        assert_eq!(minus_one[10], 0x01);
    }

    #[test]
    fn what_is_written_walks_back_field_by_field() {
        let inner = Message::new().float(2, 0.5);
        let bytes = Message::new()
            .double(1, 1.25)
            .int64(2, -7)
            .bool(3, true)
            .message(5, &inner)
            .into_bytes();
        let fields: Vec<_> = Fields::new(&bytes).collect::<Result<_, _>>().unwrap();
        assert_eq!(fields.len(), 4);
        assert_eq!((fields[0].0, fields[0].1.as_f64()), (1, Some(1.25)));
        assert_eq!((fields[1].0, fields[1].1.as_i64()), (2, Some(-7)));
        assert_eq!((fields[2].0, fields[2].1.as_i64()), (3, Some(1)));
        let nested = fields[3].1.as_bytes().unwrap();
        let (field, payload) = Fields::new(nested).next().unwrap().unwrap();
        assert_eq!((field, payload.as_f32()), (2, Some(0.5)));
    }

    #[test]
    fn a_field_running_past_its_message_is_an_error_not_a_panic() {
        let bytes = Message::new().string(1, "abcdef").into_bytes();
        for cut in 1..bytes.len() {
            let walked: Vec<_> = Fields::new(&bytes[..cut]).collect();
            assert_eq!(walked, [Err(DecodeError::Truncated)], "cut at {cut}");
        }
        let group = [0x0b]; // field 1, wire type 3 (start group)
        assert_eq!(
            Fields::new(&group).next(),
            Some(Err(DecodeError::WireType(3)))
        );
        let endless = [0xff; 11];
        assert_eq!(
            Fields::new(&endless).next(),
            Some(Err(DecodeError::LongVarint))
        );
    }
}
