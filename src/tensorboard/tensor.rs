//! A scalar read from a `TensorProto`, as TensorFlow 2's `tf.summary.scalar` writes it
//! (torch's `SummaryWriter` writes the older `simple_value` instead).
//!
//! The fields read, from `tensorboard/compat/proto/tensor.proto` and `types.proto`:
//! `dtype` (1; `DT_FLOAT` = 1, `DT_DOUBLE` = 2), `tensor_shape` (2), `tensor_content`
//! (4, the values' raw little-endian bytes), `float_val` (5) and `double_val` (6), each
//! packed or not.

use super::protobuf::{DecodeError, Fields, Payload};

const DT_FLOAT: i64 = 1;
const DT_DOUBLE: i64 = 2;

/// The single value of a `DT_FLOAT` or `DT_DOUBLE` tensor holding one value, whatever its
/// rank (a scalar summary is rank 0; a `[1]` or `[1, 1]` tensor holds one value too).
/// `None` for any other tensor: a histogram, text, an image, the hparams plugin's
/// placeholder.
pub fn scalar(tensor: &[u8]) -> Result<Option<f64>, DecodeError> {
    let mut dtype = 0;
    let mut elements = 1u64;
    let mut values: Vec<f64> = Vec::new();
    let mut content: &[u8] = &[];
    for field in Fields::new(tensor) {
        match field? {
            (1, payload) => dtype = payload.as_i64().ok_or(DecodeError::WrongType)?,
            (2, payload) => {
                elements = element_count(payload.as_bytes().ok_or(DecodeError::WrongType)?)?;
            }
            (4, payload) => content = payload.as_bytes().ok_or(DecodeError::WrongType)?,
            // Repeated numbers come packed (one run of bytes) or one per field: a reader
            // must take both.
            (5, Payload::Bytes(packed)) => {
                values.extend(fixed_width::<4>(packed)?.map(|b| f64::from(f32::from_le_bytes(b))))
            }
            (5, Payload::Fixed32(b)) => values.push(f64::from(f32::from_le_bytes(b))),
            (6, Payload::Bytes(packed)) => {
                values.extend(fixed_width::<8>(packed)?.map(f64::from_le_bytes));
            }
            (6, Payload::Fixed64(b)) => values.push(f64::from_le_bytes(b)),
            (5 | 6, _) => return Err(DecodeError::WrongType),
            _ => {}
        }
    }
    if elements != 1 {
        return Ok(None);
    }
    let value = match dtype {
        DT_FLOAT if content.len() == 4 => Some(f64::from(f32::from_le_bytes(
            content.try_into().expect("4 bytes"),
        ))),
        DT_DOUBLE if content.len() == 8 => {
            Some(f64::from_le_bytes(content.try_into().expect("8 bytes")))
        }
        // In a TensorProto's version 0, one value listed fills the whole shape.
        DT_FLOAT | DT_DOUBLE if content.is_empty() && values.len() == 1 => Some(values[0]),
        _ => None,
    };
    Ok(value)
}

/// The number of elements a `TensorShapeProto` holds: the product of its `dim` (2) sizes
/// (`Dim.size`, 1), 1 for rank 0; 0 for an unknown rank (3) or a dimension of unknown
/// size (-1), which hold no known value.
fn element_count(shape: &[u8]) -> Result<u64, DecodeError> {
    let mut count = 1u64;
    for field in Fields::new(shape) {
        match field? {
            (2, payload) => {
                let mut size = 0;
                for dim_field in Fields::new(payload.as_bytes().ok_or(DecodeError::WrongType)?) {
                    if let (1, size_payload) = dim_field? {
                        size = size_payload.as_i64().ok_or(DecodeError::WrongType)?;
                    }
                }
                count = count.saturating_mul(u64::try_from(size).unwrap_or(0));
            }
            (3, payload) if payload.as_i64() != Some(0) => return Ok(0),
            _ => {}
        }
    }
    Ok(count)
}

/// A packed run of `N`-byte values, value by value.
fn fixed_width<const N: usize>(
    packed: &[u8],
) -> Result<impl Iterator<Item = [u8; N]> + '_, DecodeError> {
    if !packed.len().is_multiple_of(N) {
        return Err(DecodeError::Truncated);
    }
    Ok(packed
        .chunks_exact(N)
        .map(|chunk| chunk.try_into().expect("N bytes")))
}

#[cfg(test)]
mod tests {
    use super::super::protobuf::Message;
    use super::*;

    fn shape(dims: &[i64]) -> Message {
        dims.iter().fold(Message::new(), |shape, &size| {
            shape.message(2, &Message::new().int64(1, size))
        })
    }

    #[test]
    fn a_float_or_double_scalar_reads_from_each_of_its_representations() {
        // tf.summary.scalar in TF 2: DT_FLOAT, rank 0, the value in float_val (packed).
        let packed_float = Message::new()
            .int64(1, DT_FLOAT)
            .message(2, &shape(&[]))
            .bytes_field(5, &1.5f32.to_le_bytes())
            .into_bytes();
        assert_eq!(scalar(&packed_float), Ok(Some(1.5)));
        let unpacked_double = Message::new()
            .int64(1, DT_DOUBLE)
            .double(6, -2.25)
            .into_bytes();
        assert_eq!(scalar(&unpacked_double), Ok(Some(-2.25)));
        let content = Message::new()
            .int64(1, DT_FLOAT)
            .message(2, &shape(&[1]))
            .bytes_field(4, &0.75f32.to_le_bytes())
            .into_bytes();
        assert_eq!(scalar(&content), Ok(Some(0.75)));
    }

    #[test]
    fn tensors_that_are_not_one_float_are_not_scalars() {
        let histogram = Message::new()
            .int64(1, DT_DOUBLE)
            .message(2, &shape(&[2, 3]))
            .bytes_field(4, &[0; 48])
            .into_bytes();
        assert_eq!(scalar(&histogram), Ok(None));
        let text = Message::new()
            .int64(1, 7) // DT_STRING
            .bytes_field(8, b"hello")
            .into_bytes();
        assert_eq!(scalar(&text), Ok(None));
        let empty = Message::new().int64(1, DT_FLOAT).into_bytes();
        assert_eq!(scalar(&empty), Ok(None));
    }
}
