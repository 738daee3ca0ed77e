//! A run file's format, told from its first bytes: a name says what its writer meant, the
//! bytes what it is.

use crate::tensorboard;

/// What a run's file can be told to be from its bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Monitor,
    Csv,
    EventFiles,
}

/// How many bytes of a file its format is told from.
pub const PREFIX_BYTES: u64 = 4096;

/// The format of a file that starts with `prefix` (its first [`PREFIX_BYTES`] or all of
/// it), or why it has none:
///
/// 1. a TFRecord header whose length's CRC checks → an event file (checked first: it is
///    the strictest test, which text cannot pass by chance);
/// 2. a first line starting `#{` → Stable-Baselines3's monitor file (its JSON comment);
/// 3. UTF-8 text without NUL bytes → a CSV, whose header decides the rest.
pub fn format(prefix: &[u8]) -> Result<Format, &'static str> {
    if prefix.is_empty() {
        return Err("an empty file");
    }
    if tensorboard::starts_like_an_event_file(prefix) {
        return Ok(Format::EventFiles);
    }
    if prefix.starts_with(b"#{") {
        return Ok(Format::Monitor);
    }
    if is_text(prefix) {
        return Ok(Format::Csv);
    }
    Err("binary, and not a TFRecord whose first header's CRC checks")
}

/// Whether `prefix` is UTF-8 text: no NUL byte, and valid but for a character the prefix
/// may have cut at its end.
fn is_text(prefix: &[u8]) -> bool {
    !prefix.contains(&0)
        && match std::str::from_utf8(prefix) {
            Ok(_) => true,
            Err(e) => e.error_len().is_none(),
        }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_are_told_from_the_bytes() {
        assert_eq!(
            format(b"#{\"t_start\": 1.0, \"env_id\": \"CartPole-v1\"}\nr,l,t\n"),
            Ok(Format::Monitor)
        );
        assert_eq!(format(b"global_step,episodic_return\n"), Ok(Format::Csv));
        // "é" (c3 a9) cut after its first byte by the prefix's end is still text.
        assert_eq!(format(b"step,r\xc3\xa9sultat\n1,\xc3"), Ok(Format::Csv));
        // A record header declaring 24 bytes, its masked CRC from TensorBoard's
        // pywrap_tensorflow.masked_crc32c(struct.pack("<Q", 24)) = 0x224b7fa3.
        let header = [24, 0, 0, 0, 0, 0, 0, 0, 0xa3, 0x7f, 0x4b, 0x22];
        assert_eq!(format(&header), Ok(Format::EventFiles));
    }

    #[test]
    fn empty_and_binary_files_have_no_format() {
        assert_eq!(format(b""), Err("an empty file"));
        assert!(format(b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR").is_err());
        // A TFRecord header whose CRC does not check is binary, not an event file.
        assert!(format(&[24, 0, 0, 0, 0, 0, 0, 0, 1, 2, 3, 4]).is_err());
        assert!(format(b"step,return\n\xff\xfe,1\n").is_err());
    }
}
