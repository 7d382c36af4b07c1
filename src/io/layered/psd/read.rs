//! Bounds-checked big-endian reading over a byte slice, and the channel decoders of PSD/PSB
//! (raw, PackBits RLE, ZIP with and without prediction), each producing exactly the
//! `width × height` bytes the channel's rectangle declares.

use crate::io::layered::LayeredError;
use std::io::Read;

/// A cursor over bytes whose every read fails with [`LayeredError::Truncated`] past the end.
pub struct Reader<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    pub fn new(data: &'a [u8]) -> Self {
        Self { data, pos: 0 }
    }

    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    pub fn take(&mut self, n: u64, what: &str) -> Result<&'a [u8], LayeredError> {
        if n > self.remaining() as u64 {
            return Err(LayeredError::Truncated {
                what: what.to_string(),
            });
        }
        let s = &self.data[self.pos..self.pos + n as usize];
        self.pos += n as usize;
        Ok(s)
    }

    /// The next `n` bytes as a reader of their own.
    pub fn sub(&mut self, n: u64, what: &str) -> Result<Reader<'a>, LayeredError> {
        Ok(Reader::new(self.take(n, what)?))
    }

    pub fn peek(&self, n: usize) -> Option<&'a [u8]> {
        self.data.get(self.pos..self.pos + n)
    }

    pub fn skip(&mut self, n: u64, what: &str) -> Result<(), LayeredError> {
        self.take(n, what).map(|_| ())
    }

    fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], LayeredError> {
        let mut a = [0; N];
        a.copy_from_slice(self.take(N as u64, what)?);
        Ok(a)
    }

    pub fn u8(&mut self, what: &str) -> Result<u8, LayeredError> {
        Ok(self.array::<1>(what)?[0])
    }

    pub fn u16(&mut self, what: &str) -> Result<u16, LayeredError> {
        Ok(u16::from_be_bytes(self.array(what)?))
    }

    pub fn i16(&mut self, what: &str) -> Result<i16, LayeredError> {
        Ok(i16::from_be_bytes(self.array(what)?))
    }

    pub fn u32(&mut self, what: &str) -> Result<u32, LayeredError> {
        Ok(u32::from_be_bytes(self.array(what)?))
    }

    pub fn i32(&mut self, what: &str) -> Result<i32, LayeredError> {
        Ok(i32::from_be_bytes(self.array(what)?))
    }

    pub fn u64(&mut self, what: &str) -> Result<u64, LayeredError> {
        Ok(u64::from_be_bytes(self.array(what)?))
    }

    /// A length field: 4 bytes in PSD, 8 in PSB where `long` (the fields the format widens).
    pub fn length(&mut self, long: bool, what: &str) -> Result<u64, LayeredError> {
        if long {
            self.u64(what)
        } else {
            self.u32(what).map(u64::from)
        }
    }
}

/// Channel compression methods.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compression {
    Raw,
    Rle,
    Zip,
    ZipPredicted,
}

impl Compression {
    pub fn from_code(code: u16, what: &str) -> Result<Self, LayeredError> {
        Ok(match code {
            0 => Self::Raw,
            1 => Self::Rle,
            2 => Self::Zip,
            3 => Self::ZipPredicted,
            _ => {
                return Err(LayeredError::Malformed(format!(
                    "{what}: unknown compression {code}"
                )))
            }
        })
    }
}

/// Decodes the first `keep` of the `planes` channels of `w`×`h` 8-bit pixels compressed as
/// `method` from `r` (for RLE, all row byte counts come first, as in the merged image; a layer
/// channel is one plane). Returns `keep × w × h` bytes: the channels sinew does not use (a
/// document may declare up to 56) are checked to be all there but never kept, so they cost no
/// memory.
pub fn decode_planes(
    r: &mut Reader,
    method: Compression,
    [w, h]: [usize; 2],
    [planes, keep]: [usize; 2],
    psb: bool,
    what: &str,
) -> Result<Vec<u8>, LayeredError> {
    let keep = keep.min(planes);
    let size = w * h * keep;
    let all = w * h * planes;
    // What is reserved before decoding: the output, but no more than the compressed data can
    // give (PackBits at most 64 bytes per byte; deflate about 1,032), so a small file declaring
    // a large image allocates only as it decodes.
    let reserve = |remaining: usize, ratio: usize| size.min(remaining.saturating_mul(ratio));
    match method {
        Compression::Raw => Ok(r.take(all as u64, what)?[..size].to_vec()),
        Compression::Rle => {
            let rows = h * planes;
            let mut counts = Vec::with_capacity(rows.min(r.remaining() / 2));
            for _ in 0..rows {
                counts.push(if psb {
                    r.u32(what)? as u64
                } else {
                    r.u16(what)? as u64
                });
            }
            let mut out = Vec::with_capacity(reserve(r.remaining(), 64));
            for (i, count) in counts.into_iter().enumerate() {
                let row = r.take(count, what)?;
                if i < h * keep {
                    unpack_bits(row, w, &mut out).map_err(|reason| {
                        LayeredError::Malformed(format!("{what}: RLE row: {reason}"))
                    })?;
                }
            }
            Ok(out)
        }
        Compression::Zip | Compression::ZipPredicted => {
            let mut out = Vec::with_capacity(reserve(r.remaining(), 1032));
            let packed = r.take(r.remaining() as u64, what)?;
            let mut zlib = flate2::read::ZlibDecoder::new(packed).take(all as u64);
            let zip_error =
                |e: std::io::Error| LayeredError::Malformed(format!("{what}: ZIP data: {e}"));
            (&mut zlib)
                .take(size as u64)
                .read_to_end(&mut out)
                .map_err(zip_error)?;
            // The channels not kept are inflated only to check that they are there.
            let rest = std::io::copy(&mut zlib, &mut std::io::sink()).map_err(zip_error)?;
            if out.len() != size || size as u64 + rest != all as u64 {
                return Err(LayeredError::Truncated {
                    what: format!("{what} (ZIP data)"),
                });
            }
            if method == Compression::ZipPredicted && w > 0 {
                for row in out.chunks_mut(w) {
                    for i in 1..row.len() {
                        row[i] = row[i].wrapping_add(row[i - 1]);
                    }
                }
            }
            Ok(out)
        }
    }
}

/// Appends one PackBits row of exactly `width` bytes to `out`.
fn unpack_bits(mut row: &[u8], width: usize, out: &mut Vec<u8>) -> Result<(), String> {
    let end = out.len() + width;
    while out.len() < end {
        let (&n, rest) = row.split_first().ok_or("ends early")?;
        row = rest;
        let n = n as i8;
        if n >= 0 {
            let count = n as usize + 1;
            if count > row.len() {
                return Err("literal run past the row's data".into());
            }
            out.extend_from_slice(&row[..count]);
            row = &row[count..];
        } else if n != -128 {
            let (&b, rest) = row.split_first().ok_or("repeat run without its byte")?;
            row = rest;
            out.extend(std::iter::repeat_n(b, (1 - n as isize) as usize));
        }
        if out.len() > end {
            return Err("run longer than the row".into());
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packbits_rows_and_refusals() {
        let mut out = Vec::new();
        // 3 literal bytes, then 4 × 9.
        unpack_bits(&[2, 1, 2, 3, 0xfd, 9], 7, &mut out).unwrap();
        assert_eq!(out, [1, 2, 3, 9, 9, 9, 9]);
        assert!(unpack_bits(&[2, 1], 3, &mut Vec::new()).is_err());
        assert!(unpack_bits(&[0xfd, 9], 2, &mut Vec::new()).is_err());
        assert!(unpack_bits(&[], 1, &mut Vec::new()).is_err());
        let mut r = Reader::new(&[0, 1]);
        assert!(matches!(r.u32("x"), Err(LayeredError::Truncated { .. })));
    }
}
