//! PyTorch's file format since 1.6 (`torch.save`): a zip archive `<name>/data.pkl` (the
//! object, pickled) beside `<name>/data/<key>` (each storage's raw bytes). Read from
//! memory, every entry bounded, nothing in the pickle run ([`super::pickle`]).

use std::io::{Cursor, Read};

use super::pickle::{self, StorageKind, Value};
use super::NamedTensor;

/// Pickles of state dicts are kilobytes; a bound keeps a doctored one from costing more.
const MAX_PICKLE_BYTES: u64 = 4 << 20;

/// A zip archive read from memory.
pub type Archive<'a> = zip::ZipArchive<Cursor<&'a [u8]>>;

/// The archive `bytes` as a zip.
pub fn archive(bytes: &[u8]) -> Result<Archive<'_>, String> {
    let zip = zip::ZipArchive::new(Cursor::new(bytes))
        .map_err(|e| format!("not a readable zip archive ({e})"))?;
    // A reader finds an archive by its last directory: in a truncated SB3 zip that is the
    // directory of a torch file stored inside it, which is not the file the user gave.
    if zip.offset() != 0 {
        return Err(format!(
            "not a readable zip archive (the only archive found starts at byte {}: the file is \
             truncated, or something precedes the archive)",
            zip.offset()
        ));
    }
    Ok(zip)
}

/// The bytes of entry `name`, at most `limit` of them; stored, not compressed (how
/// `torch.save` and Python's `zipfile` write by default).
pub fn entry(zip: &mut Archive, name: &str, limit: u64) -> Result<Vec<u8>, String> {
    let mut file = zip
        .by_name(name)
        .map_err(|e| format!("the archive has no readable entry {name} ({e})"))?;
    if file.compression() != zip::CompressionMethod::Stored {
        return Err(format!(
            "entry {name} is compressed ({}): sapnet reads archives whose entries are stored, as \
             torch.save and Python's zipfile write them",
            file.compression()
        ));
    }
    if file.size() > limit {
        return Err(format!(
            "entry {name} holds {} bytes, more than the {limit} a policy needs",
            file.size()
        ));
    }
    // The declared size is the file's word, not its bytes: a header may declare 2^62. The
    // buffer grows with what is actually read, from a start no larger than a megabyte.
    let declared = file.size();
    let mut bytes = Vec::with_capacity(declared.min(1 << 20) as usize);
    file.by_ref()
        .take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("reading entry {name}: {e}"))?;
    if bytes.len() as u64 != declared {
        return Err(format!(
            "entry {name} holds {} bytes where its header says {declared}",
            bytes.len()
        ));
    }
    Ok(bytes)
}

/// The tensors of the state dict that `torch.save` wrote into `bytes`, in the dict's order;
/// each storage read no further than the size its tensor gives it.
pub fn state_dict(bytes: &[u8]) -> Result<Vec<NamedTensor>, String> {
    state_dict_in(&mut archive(bytes)?)
}

/// [`state_dict`] of an archive already open.
pub fn state_dict_in(zip: &mut Archive) -> Result<Vec<NamedTensor>, String> {
    let names: Vec<String> = zip
        .file_names()
        .filter_map(|n| n.ok().map(|n| n.into_owned()))
        .collect();
    let pickles: Vec<&String> = names.iter().filter(|n| n.ends_with("/data.pkl")).collect();
    let pickle_name = match pickles.as_slice() {
        [one] => (*one).clone(),
        [] => {
            return Err("a zip archive without a data.pkl: not a file torch.save wrote".into());
        }
        many => {
            return Err(format!(
                "the archive holds {} pickles ({}); torch.save writes one",
                many.len(),
                many.iter()
                    .map(|s| s.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        }
    };
    let root = pickle_name.trim_end_matches("data.pkl").to_string();
    if let Ok(order) = entry(zip, &format!("{root}byteorder"), 16) {
        if order != b"little" {
            return Err(format!(
                "the storages are {}-endian; sapnet reads little-endian files",
                String::from_utf8_lossy(&order)
            ));
        }
    }
    let object = pickle::read(&entry(zip, &pickle_name, MAX_PICKLE_BYTES)?)
        .map_err(|e| format!("{pickle_name}: {e}"))?;
    let Value::Dict(dict) = object else {
        return Err(format!(
            "{pickle_name} holds a pickled object that is not a state dict (a dict of tensors): \
             save `model.state_dict()`"
        ));
    };
    let dict = dict.borrow();
    let mut tensors = Vec::with_capacity(dict.items.len());
    for (key, value) in dict.items.iter() {
        let Value::Str(key) = key else {
            return Err(format!(
                "{pickle_name}: a key of the state dict is not a string"
            ));
        };
        let Value::Tensor(t) = value else {
            return Err(format!(
                "`{key}` is not a tensor: a state dict of a network holds only tensors (a \
                 checkpoint holding several objects? save the network's state_dict() alone)"
            ));
        };
        let dtype = match t.storage.kind {
            StorageKind::F32 => "float32",
            StorageKind::Other(kind) => {
                return Err(format!(
                    "tensor `{key}` is stored as torch.{kind}; sapnet's Q-networks are float32 \
                     (convert with `.float()` before saving)"
                ))
            }
        };
        // Sizes come from the file: checked, so that a doctored one cannot overflow them.
        let numel = t
            .shape
            .iter()
            .try_fold(1usize, |n, d| n.checked_mul(*d))
            .ok_or_else(|| format!("tensor `{key}` has an impossible shape {:?}", t.shape))?;
        let storage_bytes = t.storage.numel.checked_mul(4).ok_or_else(|| {
            format!(
                "tensor `{key}`'s storage claims {} elements",
                t.storage.numel
            )
        })?;
        let contiguous = row_major_strides(&t.shape) == t.stride || numel <= 1;
        if !contiguous {
            return Err(format!(
                "tensor `{key}` is a strided view (stride {:?} for shape {:?}); save a \
                 contiguous copy (`.contiguous()`)",
                t.stride, t.shape
            ));
        }
        let end = t
            .offset
            .checked_add(numel)
            .filter(|e| *e <= t.storage.numel);
        if end.is_none() {
            return Err(format!(
                "tensor `{key}` ({} {dtype} from offset {}) runs past its storage of {}",
                numel, t.offset, t.storage.numel
            ));
        }
        let data_name = format!("{root}data/{}", t.storage.key);
        let storage = entry(zip, &data_name, storage_bytes as u64)?;
        if storage.len() != storage_bytes {
            return Err(format!(
                "storage {data_name} holds {} bytes, its tensor `{key}` says {storage_bytes}",
                storage.len(),
            ));
        }
        let values = storage[4 * t.offset..4 * (t.offset + numel)]
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        tensors.push(NamedTensor {
            name: key.to_string(),
            shape: t.shape.clone(),
            values,
        });
    }
    Ok(tensors)
}

fn row_major_strides(shape: &[usize]) -> Vec<usize> {
    let mut strides = vec![1; shape.len()];
    for i in (0..shape.len().saturating_sub(1)).rev() {
        strides[i] = strides[i + 1] * shape[i + 1];
    }
    strides
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A zip of one stored entry `data/0` holding `data`, whose local and central headers
    /// declare `declared` bytes (through the zip64 extra field, as a file may lie).
    fn lying_zip(data: &[u8], declared: u64) -> Vec<u8> {
        let name = b"data/0";
        // CRC-32 (IEEE), bit by bit: a test's few bytes.
        let crc = !data.iter().fold(!0u32, |mut crc, &byte| {
            crc ^= u32::from(byte);
            for _ in 0..8 {
                crc = (crc >> 1) ^ (0xEDB8_8320 & (crc & 1).wrapping_neg());
            }
            crc
        });
        // The zip64 extra field: the uncompressed size only (the 32-bit field is 0xFFFFFFFF).
        let extra = [
            &1u16.to_le_bytes()[..],
            &8u16.to_le_bytes(),
            &declared.to_le_bytes(),
        ]
        .concat();
        let mut zip = Vec::new();
        let header = |zip: &mut Vec<u8>, signature: u32, central: bool| {
            zip.extend(signature.to_le_bytes());
            if central {
                zip.extend(45u16.to_le_bytes()); // made by
            }
            zip.extend(45u16.to_le_bytes()); // needed
            zip.extend([0u8; 2]); // flags
            zip.extend([0u8; 2]); // stored
            zip.extend([0u8; 4]); // time, date
            zip.extend(crc.to_le_bytes());
            zip.extend((data.len() as u32).to_le_bytes()); // compressed
            zip.extend(u32::MAX.to_le_bytes()); // uncompressed: see the extra field
            zip.extend((name.len() as u16).to_le_bytes());
            zip.extend((extra.len() as u16).to_le_bytes());
            if central {
                zip.extend([0u8; 2]); // comment
                zip.extend([0u8; 2]); // disk
                zip.extend([0u8; 2]); // internal attributes
                zip.extend([0u8; 4]); // external attributes
                zip.extend(0u32.to_le_bytes()); // the local header's offset
            }
            zip.extend(name);
            zip.extend(&extra);
        };
        header(&mut zip, 0x0403_4b50, false);
        zip.extend(data);
        let central = zip.len();
        header(&mut zip, 0x0201_4b50, true);
        let size = zip.len() - central;
        zip.extend(0x0605_4b50u32.to_le_bytes());
        zip.extend([0u8; 4]); // disks
        zip.extend(1u16.to_le_bytes());
        zip.extend(1u16.to_le_bytes());
        zip.extend((size as u32).to_le_bytes());
        zip.extend((central as u32).to_le_bytes());
        zip.extend([0u8; 2]);
        zip
    }

    /// Issue 34, item 6: an entry of 128 bytes declaring 2^62 aborted the import (the
    /// declared size was allocated before reading); it is refused for what it holds.
    #[test]
    fn an_entry_is_read_for_the_bytes_it_holds_not_the_size_it_declares() {
        let bytes = lying_zip(&[7u8; 128], 1 << 62);
        let mut zip = archive(&bytes).unwrap();
        let err = entry(&mut zip, "data/0", u64::MAX).unwrap_err();
        assert!(
            err.contains("data/0") && err.contains("header says"),
            "{err}"
        );
        // The same entry telling the truth reads back.
        let honest = lying_zip(&[7u8; 128], 128);
        let mut zip = archive(&honest).unwrap();
        assert_eq!(entry(&mut zip, "data/0", 1024).unwrap(), vec![7u8; 128]);
    }
}
