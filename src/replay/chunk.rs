//! A chunk's records, unpacked with every length checked first.
//!
//! The whole chunk is decompressed into one buffer of exactly the size its
//! header declares (the caller has already bounded that size by the record
//! cap); the decompressor is never allowed to write past it. Its CRC is
//! checked, then each inner record's length is checked against the bytes
//! left in that buffer before anything is sliced, so no length read from a
//! corrupt chunk can make an allocation.

use std::io::Read;

use mcap::records::{ChunkHeader, Record};

/// Bytes of an inner record's opcode and length.
const RECORD_HEAD_BYTES: usize = 9;

/// The records of one chunk, or why it cannot be read (one line).
pub(crate) fn unpack(header: &ChunkHeader, data: &[u8]) -> Result<Vec<Record<'static>>, String> {
    let declared = usize::try_from(header.uncompressed_size).map_err(|_| {
        format!(
            "declares {} uncompressed bytes, more than this machine can address",
            header.uncompressed_size
        )
    })?;
    let owned;
    let unpacked: &[u8] = match header.compression.as_str() {
        "" => {
            if data.len() != declared {
                return Err(format!(
                    "an uncompressed chunk holds {} bytes but declares {declared}",
                    data.len()
                ));
            }
            data
        }
        "zstd" => {
            // Fails rather than writes past `declared`.
            owned = zstd::bulk::decompress(data, declared).map_err(|e| {
                format!("zstd data does not decompress within its declared {declared} bytes: {e}")
            })?;
            &owned
        }
        "lz4" => {
            let mut out = Vec::with_capacity(declared);
            lz4::Decoder::new(data)
                .and_then(|d| d.take(declared as u64 + 1).read_to_end(&mut out))
                .map_err(|e| format!("lz4 data does not decompress: {e}"))?;
            owned = out;
            &owned
        }
        other => {
            return Err(format!(
            "a chunk is compressed with `{other}`; replay reads uncompressed, lz4 and zstd chunks"
        ))
        }
    };
    if unpacked.len() != declared {
        return Err(format!(
            "decompresses to {}{} bytes but declares {declared}",
            if unpacked.len() > declared {
                "more than "
            } else {
                ""
            },
            unpacked.len().min(declared)
        ));
    }
    if header.uncompressed_crc != 0 {
        let crc = crc32fast::hash(unpacked);
        if crc != header.uncompressed_crc {
            return Err(format!(
                "the unpacked chunk's CRC is {crc:#010x}, its header says {:#010x}",
                header.uncompressed_crc
            ));
        }
    }
    let mut records = Vec::new();
    let mut rest = unpacked;
    while !rest.is_empty() {
        let k = records.len();
        let at = declared - rest.len();
        if rest.len() < RECORD_HEAD_BYTES {
            return Err(format!(
                "record {k} of this chunk (byte {at} unpacked): {} bytes left, a record head takes {RECORD_HEAD_BYTES}",
                rest.len()
            ));
        }
        let opcode = rest[0];
        let mut len_bytes = [0u8; 8];
        len_bytes.copy_from_slice(&rest[1..RECORD_HEAD_BYTES]);
        let len = u64::from_le_bytes(len_bytes);
        let left = rest.len() - RECORD_HEAD_BYTES;
        if len > left as u64 {
            return Err(format!(
                "record {k} of this chunk (byte {at} unpacked) declares {len} bytes, only {left} are left in the chunk"
            ));
        }
        let len = len as usize;
        let body = &rest[RECORD_HEAD_BYTES..RECORD_HEAD_BYTES + len];
        let record = mcap::parse_record(opcode, body)
            .map_err(|e| format!("record {k} of this chunk (byte {at} unpacked): {e}"))?;
        records.push(record.into_owned());
        rest = &rest[RECORD_HEAD_BYTES + len..];
    }
    Ok(records)
}
