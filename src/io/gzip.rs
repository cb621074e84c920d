//! gzip under a hard limit, for `.nii.gz` and NRRD's gzip encoding.
//!
//! A few kilobytes of deflate can claim gigabytes, so nothing here inflates "to the end": the
//! caller says how many bytes the header declares, the stream is read through
//! `Read::take(declared + 1)`, and a byte past the declared size is an error, never more memory.

use std::io::{ErrorKind, Read, Take};

use flate2::bufread::MultiGzDecoder;

use super::{Format, LoadError, Location};

/// The most deflate can expand its input: a 258-byte match coded in two bits. A header that
/// declares more inflated bytes than this times the compressed size cannot be telling the truth.
pub(super) const MAX_RATIO: u64 = 1032;

/// Whether `bytes` start with the gzip magic (0x1f 0x8b).
pub(super) fn is_gzip(bytes: &[u8]) -> bool {
    bytes.starts_with(&[0x1f, 0x8b])
}

/// A gzip stream (one or more members) read under a byte limit, with every failure turned into
/// a [`LoadError`] that says how far the stream got.
pub(super) struct Inflater<'a> {
    reader: Take<MultiGzDecoder<&'a [u8]>>,
    format: Format,
    compressed_len: usize,
    /// Bytes inflated so far.
    produced: u64,
    /// Bytes the stream must inflate to, once the caller knows (`None` while reading a header).
    declared: Option<u64>,
}

impl<'a> Inflater<'a> {
    /// Starts inflating `compressed`; until [`Inflater::expect_total`], reads are bounded only
    /// by the callers' buffers.
    pub(super) fn new(compressed: &'a [u8], format: Format) -> Self {
        Self {
            reader: MultiGzDecoder::new(compressed).take(u64::MAX),
            format,
            compressed_len: compressed.len(),
            produced: 0,
            declared: None,
        }
    }

    /// Refuses a declared size that the compressed bytes could not inflate to, before anyone
    /// allocates for it.
    pub(super) fn check_ratio(&self, declared: u64, what: &'static str) -> Result<(), LoadError> {
        let possible = (self.compressed_len as u64).saturating_mul(MAX_RATIO);
        if declared > possible {
            return Err(LoadError::CountTooLarge {
                format: self.format,
                what,
                claimed: declared,
                possible,
            });
        }
        Ok(())
    }

    /// From now on the stream must inflate to exactly `total` bytes (counting those already
    /// read): reading stops one byte past it.
    pub(super) fn expect_total(&mut self, total: u64) {
        self.declared = Some(total);
        let left = total.saturating_sub(self.produced).saturating_add(1);
        self.reader.set_limit(left);
    }

    /// Reads up to `buf.len()` bytes; 0 only at the end of the stream (or of the limit).
    pub(super) fn read_some(&mut self, buf: &mut [u8]) -> Result<usize, LoadError> {
        loop {
            match self.reader.read(buf) {
                Ok(n) => {
                    self.produced += n as u64;
                    return Ok(n);
                }
                Err(e) if e.kind() == ErrorKind::Interrupted => continue,
                Err(e) if e.kind() == ErrorKind::UnexpectedEof => return Err(self.truncated()),
                Err(e) => return Err(self.corrupt(&e)),
            }
        }
    }

    /// Fills as much of `buf` as the stream holds; returns how much that was.
    pub(super) fn read_up_to(&mut self, buf: &mut [u8]) -> Result<usize, LoadError> {
        let mut filled = 0;
        while filled < buf.len() {
            match self.read_some(&mut buf[filled..])? {
                0 => break,
                n => filled += n,
            }
        }
        Ok(filled)
    }

    /// Fills `buf` completely, or reports the stream as truncated.
    pub(super) fn read_exact(&mut self, buf: &mut [u8]) -> Result<(), LoadError> {
        if self.read_up_to(buf)? < buf.len() {
            return Err(self.truncated());
        }
        Ok(())
    }

    /// Reads and drops `count` bytes (padding between a header and its data).
    pub(super) fn skip(&mut self, mut count: u64) -> Result<(), LoadError> {
        let mut scratch = [0u8; 4096];
        while count > 0 {
            let n = count.min(scratch.len() as u64) as usize;
            self.read_exact(&mut scratch[..n])?;
            count -= n as u64;
        }
        Ok(())
    }

    /// After the declared bytes: the stream must end here (and its checksum must match).
    pub(super) fn finish(mut self) -> Result<(), LoadError> {
        let mut probe = [0u8; 1];
        if self.read_some(&mut probe)? > 0 {
            return Err(self.too_long());
        }
        Ok(())
    }

    /// The error for a stream whose inflated size already passes `total`.
    pub(super) fn too_long(&self) -> LoadError {
        let declared = self.declared.unwrap_or(self.produced);
        LoadError::Syntax {
            format: self.format,
            location: Location::Item("inflated byte", declared as usize),
            detail: format!(
                "the gzip stream inflates past the {declared} bytes the header declares"
            ),
        }
    }

    /// The error for a stream that ended before the declared size.
    pub(super) fn truncated(&self) -> LoadError {
        let wanted = match self.declared {
            Some(d) => format!("; the header declares {d}"),
            None => String::new(),
        };
        LoadError::Truncated {
            format: self.format,
            offset: self.compressed_len,
            detail: format!(
                "the gzip stream is truncated: it ends after {} inflated bytes{wanted}",
                self.produced
            ),
        }
    }

    fn corrupt(&self, e: &std::io::Error) -> LoadError {
        LoadError::Syntax {
            format: self.format,
            location: Location::Item("inflated byte", self.produced as usize),
            detail: format!("corrupt gzip data ({e})"),
        }
    }
}
