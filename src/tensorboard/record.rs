//! TFRecord framing, the container of an event file: each record is
//!
//! ```text
//! u64 length (little-endian) | u32 masked CRC-32C of those 8 bytes | data | u32 masked CRC-32C of data
//! ```
//!
//! The CRC is masked (rotated and offset) because TensorFlow found that a CRC computed over
//! bytes that themselves hold CRCs is weak; every TFRecord writer and reader masks it.

use std::io::{self, Read, Write};

use crc::{Crc, CRC_32_ISCSI};

/// CRC-32C, the Castagnoli polynomial (named iSCSI in the CRC catalogue).
const CRC32C: Crc<u32> = Crc::<u32>::new(&CRC_32_ISCSI);

/// Bytes before a record's data: its length and the length's CRC.
pub const HEADER_BYTES: usize = 12;

/// Bytes after a record's data: the data's CRC.
pub const FOOTER_BYTES: usize = 4;

/// The largest record read: an event holds a summary of scalars, images or histograms, far
/// below this; a larger length is taken for corruption rather than allocated.
pub const MAX_RECORD_BYTES: u64 = 1 << 30;

/// TensorFlow's masked CRC-32C of `bytes`.
pub fn masked_crc(bytes: &[u8]) -> u32 {
    let crc = CRC32C.checksum(bytes);
    crc.rotate_right(15).wrapping_add(0xa282_ead8)
}

/// Writes `data` as one record.
pub fn write(out: &mut impl Write, data: &[u8]) -> io::Result<()> {
    let length = (data.len() as u64).to_le_bytes();
    out.write_all(&length)?;
    out.write_all(&masked_crc(&length).to_le_bytes())?;
    out.write_all(data)?;
    out.write_all(&masked_crc(data).to_le_bytes())
}

/// The data length a record header declares, if the header's CRC checks.
pub fn declared_length(header: &[u8; HEADER_BYTES]) -> Option<u64> {
    let (length, crc) = header.split_at(8);
    let crc = u32::from_le_bytes(crc.try_into().expect("4 bytes"));
    (masked_crc(length) == crc).then(|| u64::from_le_bytes(length.try_into().expect("8 bytes")))
}

/// What is wrong with a record, at the byte offset where the record starts.
#[derive(Debug, thiserror::Error)]
pub enum Corruption {
    #[error("the record's header ends the file after {0} of its 12 bytes")]
    TruncatedHeader(usize),
    #[error("the CRC-32C of the record's length does not check")]
    LengthCrc,
    #[error("the record declares {declared} bytes of data; {left} are left in the file")]
    TooLong { declared: u64, left: u64 },
    #[error(
        "the record declares {0} bytes of data, more than the {MAX_RECORD_BYTES} an event may hold"
    )]
    Oversized(u64),
    #[error("the CRC-32C of the record's data does not check")]
    DataCrc,
}

/// Failure to read a record: the file's own error, or a record that is not well formed.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    #[error(transparent)]
    Io(#[from] io::Error),
    #[error(transparent)]
    Corrupt(#[from] Corruption),
}

/// Reads records one by one from `input`, which holds `len` bytes from where it starts.
/// A record may declare any length: it is checked against the bytes left, and against
/// [`MAX_RECORD_BYTES`], before anything is allocated for it.
#[derive(Debug)]
pub struct Records<R> {
    input: R,
    len: u64,
    offset: u64,
    data: Vec<u8>,
}

impl<R: Read> Records<R> {
    pub fn new(input: R, len: u64) -> Self {
        Self {
            input,
            len,
            offset: 0,
            data: Vec::new(),
        }
    }

    /// The next record as `(its offset, its data)`, or `None` at the end of the input.
    /// The data is borrowed until the next call.
    pub fn next_record(&mut self) -> Result<Option<(u64, &[u8])>, RecordError> {
        let start = self.offset;
        let left = self.len - start;
        if left == 0 {
            return Ok(None);
        }
        if left < HEADER_BYTES as u64 {
            return Err(Corruption::TruncatedHeader(left as usize).into());
        }
        let mut header = [0; HEADER_BYTES];
        self.input.read_exact(&mut header)?;
        let declared = declared_length(&header).ok_or(Corruption::LengthCrc)?;
        let left = left - HEADER_BYTES as u64;
        if declared.saturating_add(FOOTER_BYTES as u64) > left {
            return Err(Corruption::TooLong { declared, left }.into());
        }
        if declared > MAX_RECORD_BYTES {
            return Err(Corruption::Oversized(declared).into());
        }
        self.data.clear();
        // Bounded by the bytes left and by MAX_RECORD_BYTES, checked above.
        self.data.resize(declared as usize, 0);
        self.input.read_exact(&mut self.data)?;
        let mut footer = [0; FOOTER_BYTES];
        self.input.read_exact(&mut footer)?;
        if masked_crc(&self.data) != u32::from_le_bytes(footer) {
            return Err(Corruption::DataCrc.into());
        }
        self.offset = start + (HEADER_BYTES + FOOTER_BYTES) as u64 + declared;
        Ok(Some((start, &self.data)))
    }

    /// The offset of the next record: after an error, the offset of the record at fault.
    pub fn offset(&self) -> u64 {
        self.offset
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_masked_crc_matches_tensorflows() {
        // CRC-32C's check value: crc32c(b"123456789") = 0xe3069283 (the CRC catalogue).
        assert_eq!(CRC32C.checksum(b"123456789"), 0xe306_9283);
        // Masked as TensorFlow's crc32c::Mask does:
        // ((0xe3069283 >> 15) | (0xe3069283 << 17)) + 0xa282ead8 (mod 2^32)
        //   = 0x2507_c60d + 0xa282_ead8 = 0xc78a_b0e5, as TensorBoard computes it:
        // tensorboard.compat.tensorflow_stub.pywrap_tensorflow.masked_crc32c(b"123456789").
        assert_eq!(masked_crc(b"123456789"), 0xc78a_b0e5);
    }

    #[test]
    fn records_read_back_with_their_offsets() {
        let mut file = Vec::new();
        write(&mut file, b"first").unwrap();
        write(&mut file, b"").unwrap();
        write(&mut file, b"third record").unwrap();
        let mut records = Records::new(file.as_slice(), file.len() as u64);
        let mut seen = Vec::new();
        while let Some((offset, data)) = records.next_record().unwrap() {
            seen.push((offset, data.to_vec()));
        }
        assert_eq!(
            seen,
            [
                (0, b"first".to_vec()),
                (21, b"".to_vec()),
                (37, b"third record".to_vec())
            ]
        );
    }

    #[test]
    fn a_declared_length_past_the_end_is_refused_before_any_allocation() {
        let mut file = Vec::new();
        let huge = u64::MAX.to_le_bytes();
        file.extend_from_slice(&huge);
        file.extend_from_slice(&masked_crc(&huge).to_le_bytes());
        file.extend_from_slice(b"tiny");
        let mut records = Records::new(file.as_slice(), file.len() as u64);
        let err = records.next_record().unwrap_err();
        assert!(
            matches!(
                err,
                RecordError::Corrupt(Corruption::TooLong {
                    declared: u64::MAX,
                    left: 4
                })
            ),
            "{err:?}"
        );
    }

    #[test]
    fn a_flipped_bit_in_the_length_or_the_data_fails_its_crc() {
        let mut file = Vec::new();
        write(&mut file, b"data").unwrap();
        let mut length_flipped = file.clone();
        length_flipped[0] ^= 1;
        let mut data_flipped = file.clone();
        data_flipped[HEADER_BYTES] ^= 1;
        let err = |bytes: &[u8]| {
            Records::new(bytes, bytes.len() as u64)
                .next_record()
                .unwrap_err()
        };
        assert!(matches!(
            err(&length_flipped),
            RecordError::Corrupt(Corruption::LengthCrc)
        ));
        assert!(matches!(
            err(&data_flipped),
            RecordError::Corrupt(Corruption::DataCrc)
        ));
        assert!(matches!(
            err(&file[..7]),
            RecordError::Corrupt(Corruption::TruncatedHeader(7))
        ));
    }
}
