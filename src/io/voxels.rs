//! Voxel bytes into label codes, chunk by chunk: both label-map parsers feed their (raw or
//! inflated) voxel data here in pieces of any size, and only the two-byte codes are kept.
//!
//! Codes are dense per layer: code 0 is value 0 (background), the others numbered in order of
//! first appearance while decoding and renumbered by value at the end.

use std::collections::HashMap;

use super::gzip::Inflater;
use super::label_map::{Affine, LabelLayer, LabelMapOptions, DEFAULT_LEVEL, MAX_LABELS};
use super::label_map_checks::{for_each_sample, Value, VoxelLayout};
use super::{Format, LoadError};

/// A file's grid and its voxels, fed into the sink the caller made for them, with what else
/// the format's reader found on the way (`meta`: NIfTI's extensions, NRRD's header).
pub(super) struct Streamed<S, M = ()> {
    pub layout: VoxelLayout,
    pub affine: Affine,
    pub sink: S,
    pub meta: M,
}

impl<S, M> Streamed<S, M> {
    /// The grid and voxels alone, for readers that need nothing else of the format.
    pub fn plain(self) -> Streamed<S> {
        let Streamed {
            layout,
            affine,
            sink,
            ..
        } = self;
        Streamed {
            layout,
            affine,
            sink,
            meta: (),
        }
    }
}

/// What voxel bytes are decoded into: label codes ([`VoxelSink`]) or an image's intensities
/// ([`super::intensity`]). Chunks come in file order, of any size.
pub(super) trait Feed {
    fn feed(&mut self, bytes: &[u8]) -> Result<(), LoadError>;
}

impl Feed for VoxelSink {
    fn feed(&mut self, bytes: &[u8]) -> Result<(), LoadError> {
        VoxelSink::feed(self, bytes)
    }
}

/// Decodes the declared voxel bytes from a gzip stream into `sink`, then checks the stream ends.
pub(super) fn decode_gzip(
    mut inflater: Inflater<'_>,
    sink: &mut impl Feed,
    remaining: u64,
) -> Result<(), LoadError> {
    feed_from_gzip(&mut inflater, sink, remaining)?;
    inflater.finish()
}

/// Decodes the next `remaining` inflated bytes into `sink`, leaving the rest of the stream
/// unread (for formats with a footer after the voxels).
pub(super) fn feed_from_gzip(
    inflater: &mut Inflater<'_>,
    sink: &mut impl Feed,
    mut remaining: u64,
) -> Result<(), LoadError> {
    let mut buf = vec![0u8; 1 << 18];
    while remaining > 0 {
        let want = remaining.min(buf.len() as u64) as usize;
        let n = inflater.read_some(&mut buf[..want])?;
        if n == 0 {
            return Err(inflater.truncated());
        }
        sink.feed(&buf[..n])?;
        remaining -= n as u64;
    }
    Ok(())
}

/// Whole numbers as labels: a value within this (relative) distance of an integer is that
/// integer, so a slope like 1/3 applied to 3, 6, 9 still gives 1, 2, 3.
const WHOLE_TOLERANCE: f64 = 1e-6;
/// Beyond this, f64 no longer holds every integer.
const MAX_EXACT: f64 = 9_007_199_254_740_992.0;

/// Values from `TABLE_MIN` up to `u16::MAX` (every 8- and 16-bit label) find their code by
/// direct lookup; others through a (SipHash, so flooding-proof) map.
const TABLE_MIN: i64 = i16::MIN as i64;
const TABLE_LEN: usize = (u16::MAX as i64 - TABLE_MIN + 1) as usize;
/// Layers with fewer voxels than this skip the table (192 KiB): a file of many tiny layers must
/// not cost far more memory than its codes.
const TABLE_MIN_VOXELS: usize = 1 << 16;

/// A layer met more than [`MAX_LABELS`] distinct values.
struct TooManyLabels;

/// The values met so far and their codes.
struct Codebook {
    /// By code; `values[0]` is 0.
    values: Vec<i64>,
    /// Code by `value - TABLE_MIN` (0: none yet, as no other value has code 0); empty when
    /// the layer is too small to want it.
    table: Vec<u16>,
    other: HashMap<i64, u16>,
}

impl Codebook {
    fn new(voxels: usize) -> Self {
        Codebook {
            values: vec![0],
            table: if voxels >= TABLE_MIN_VOXELS {
                vec![0; TABLE_LEN]
            } else {
                Vec::new()
            },
            other: HashMap::new(),
        }
    }

    fn code_of(&mut self, value: i64) -> Result<u16, TooManyLabels> {
        if value == 0 {
            return Ok(0);
        }
        let slot = usize::try_from(value - TABLE_MIN)
            .ok()
            .and_then(|at| self.table.get_mut(at));
        let known = match slot.as_deref() {
            Some(&code) => Some(code).filter(|&c| c != 0),
            None => self.other.get(&value).copied(),
        };
        if let Some(code) = known {
            return Ok(code);
        }
        if self.values.len() > MAX_LABELS {
            return Err(TooManyLabels);
        }
        let code = self.values.len() as u16;
        self.values.push(value);
        match slot {
            Some(entry) => *entry = code,
            None => {
                self.other.insert(value, code);
            }
        }
        Ok(code)
    }
}

/// One layer's codes as they are decoded.
struct LayerCoder {
    codes: Vec<u16>,
    book: Codebook,
    /// The last value coded and its code: label maps are mostly long runs of one value.
    last: (i64, u16),
    level: f64,
    /// Read as a mask (thresholded at `level`) rather than as whole-number labels.
    mask: bool,
}

impl LayerCoder {
    fn new(
        voxels: usize,
        level: f64,
        mask: bool,
    ) -> Result<Self, std::collections::TryReserveError> {
        let mut codes = Vec::new();
        codes.try_reserve_exact(voxels)?;
        Ok(Self {
            codes,
            book: Codebook::new(voxels),
            last: (0, 0),
            level,
            mask,
        })
    }

    #[inline]
    fn push_label(&mut self, value: i64) -> Result<(), TooManyLabels> {
        if value != self.last.0 {
            self.last = (value, self.book.code_of(value)?);
        }
        self.codes.push(self.last.1);
        Ok(())
    }

    #[inline]
    fn push_real(&mut self, v: f64) -> Result<(), TooManyLabels> {
        if self.mask {
            return self.push_label(i64::from(v >= self.level));
        }
        if v.is_nan() {
            return self.push_label(0);
        }
        let whole = v.round();
        if (v - whole).abs() <= WHOLE_TOLERANCE * whole.abs().max(1.0) && whole.abs() <= MAX_EXACT {
            return self.push_label(whole as i64);
        }
        self.become_mask();
        self.push_real(v)
    }

    /// The first value that is not a whole number: the image is a mask after all, so the codes
    /// so far are thresholded too.
    fn become_mask(&mut self) {
        let mut book = Codebook::new(0);
        let level = self.level;
        // Two values at most: this cannot run out of codes.
        let remap: Vec<u16> = (self.book.values.iter())
            .map(|&v| book.code_of(i64::from(v as f64 >= level)).unwrap_or(0))
            .collect();
        for c in &mut self.codes {
            *c = remap[*c as usize];
        }
        self.book = book;
        self.last = (0, 0);
        self.mask = true;
    }

    /// Renumbers the codes so that values are sorted (background stays code 0).
    fn finish(self) -> LabelLayer {
        let (mut codes, values) = (self.codes, self.book.values);
        let mut order: Vec<usize> = (1..values.len()).collect();
        order.sort_unstable_by_key(|&c| values[c]);
        if order.iter().enumerate().all(|(rank, &c)| c == rank + 1) {
            return LabelLayer { codes, values };
        }
        let mut remap = vec![0u16; values.len()];
        for (rank, &old) in order.iter().enumerate() {
            remap[old] = (rank + 1) as u16;
        }
        for c in &mut codes {
            *c = remap[*c as usize];
        }
        let sorted = std::iter::once(0).chain(order.iter().map(|&c| values[c]));
        LabelLayer {
            codes,
            values: sorted.collect(),
        }
    }
}

/// Turns a file's voxel bytes, fed in chunks of any size, into label layers.
pub(super) struct VoxelSink {
    layout: VoxelLayout,
    format: Format,
    layers: Vec<LayerCoder>,
    /// Integer samples read as they are (no scaling), without going through f64.
    exact: bool,
    /// Bytes of one step: a sample, or one sample of every layer when interleaved.
    unit: usize,
    /// The start of a step split between two chunks.
    pending: Vec<u8>,
    /// Samples of one layer gathered from interleaved steps.
    scratch: Vec<u8>,
    /// The layer being filled (layers one after another).
    current: usize,
}

impl VoxelSink {
    /// Reserves the codes; refuses layouts past the size limits (the caller has also checked
    /// the sizes against the bytes).
    pub(super) fn new(
        layout: &VoxelLayout,
        options: &LabelMapOptions,
        format: Format,
    ) -> Result<Self, LoadError> {
        layout.data_bytes(format)?;
        let (slope, inter) = (layout.slope, layout.inter);
        let fractional = slope.fract() != 0.0 || inter.fract() != 0.0;
        let exact = !layout.sample.is_float() && slope == 1.0 && inter == 0.0;
        let mask = options.level.is_some() && (layout.sample.is_float() || fractional);
        let level = options.level.unwrap_or(DEFAULT_LEVEL);
        let voxels = layout.voxel_count();
        let layers = (0..layout.layers)
            .map(|_| LayerCoder::new(voxels, level, mask))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|_| LoadError::Unsupported {
                format,
                detail: format!(
                    "cannot allocate {} bytes for the label codes",
                    voxels as u128 * 2 * layout.layers as u128
                ),
            })?;
        let interleaved = layout.interleaved && layout.layers > 1;
        let unit = layout.sample.size() * if interleaved { layout.layers } else { 1 };
        Ok(Self {
            layout: VoxelLayout {
                interleaved,
                ..*layout
            },
            format,
            layers,
            exact,
            unit,
            pending: Vec::with_capacity(unit),
            scratch: Vec::new(),
            current: 0,
        })
    }

    /// Decodes the next bytes of voxel data.
    pub(super) fn feed(&mut self, mut bytes: &[u8]) -> Result<(), LoadError> {
        if !self.pending.is_empty() {
            let take = (self.unit - self.pending.len()).min(bytes.len());
            self.pending.extend_from_slice(&bytes[..take]);
            bytes = &bytes[take..];
            if self.pending.len() < self.unit {
                return Ok(());
            }
            let step = std::mem::take(&mut self.pending);
            self.feed_steps(&step)?;
            self.pending = step;
            self.pending.clear();
        }
        let whole = bytes.len() / self.unit * self.unit;
        self.feed_steps(&bytes[..whole])?;
        self.pending.extend_from_slice(&bytes[whole..]);
        Ok(())
    }

    /// Whole steps only.
    fn feed_steps(&mut self, mut bytes: &[u8]) -> Result<(), LoadError> {
        if self.layout.interleaved {
            return self.feed_interleaved(bytes);
        }
        let voxels = self.layout.voxel_count();
        let size = self.layout.sample.size();
        while !bytes.is_empty() && self.current < self.layers.len() {
            let layer = &mut self.layers[self.current];
            let n = (voxels - layer.codes.len()).min(bytes.len() / size);
            decode_run(layer, &bytes[..n * size], &self.layout, self.exact)
                .map_err(|_| too_many(self.format, self.current))?;
            bytes = &bytes[n * size..];
            if layer.codes.len() == voxels {
                self.current += 1;
            }
        }
        Ok(())
    }

    fn feed_interleaved(&mut self, bytes: &[u8]) -> Result<(), LoadError> {
        let size = self.layout.sample.size();
        let room = self.layout.voxel_count() - self.layers[0].codes.len();
        let steps = &bytes[..(bytes.len() / self.unit).min(room) * self.unit];
        for (l, layer) in self.layers.iter_mut().enumerate() {
            self.scratch.clear();
            for step in steps.chunks_exact(self.unit) {
                self.scratch
                    .extend_from_slice(&step[l * size..(l + 1) * size]);
            }
            decode_run(layer, &self.scratch, &self.layout, self.exact)
                .map_err(|_| too_many(self.format, l))?;
        }
        Ok(())
    }

    /// The layers, once every voxel has come; an error if none is labelled.
    pub(super) fn finish(self) -> Result<Vec<LabelLayer>, LoadError> {
        let voxels = self.layout.voxel_count();
        if let Some(short) = self.layers.iter().find(|l| l.codes.len() < voxels) {
            return Err(LoadError::Truncated {
                format: self.format,
                offset: 0,
                detail: format!(
                    "the voxel data ends after {} of {voxels} voxels",
                    short.codes.len()
                ),
            });
        }
        if self.layers.iter().all(|l| l.book.values.len() == 1) {
            return Err(LoadError::Unsupported {
                format: self.format,
                detail: "the label map is empty: every voxel is background (0, or below the \
                         mask level)"
                    .into(),
            });
        }
        Ok(self.layers.into_iter().map(LayerCoder::finish).collect())
    }
}

fn too_many(format: Format, layer: usize) -> LoadError {
    LoadError::Unsupported {
        format,
        detail: format!("layer {layer} holds more than {MAX_LABELS} distinct labels"),
    }
}

/// Decodes whole samples of one layer: integers exactly where `exact`, else after scaling.
fn decode_run(
    layer: &mut LayerCoder,
    bytes: &[u8],
    layout: &VoxelLayout,
    exact: bool,
) -> Result<(), TooManyLabels> {
    let (slope, inter) = (layout.slope, layout.inter);
    for_each_sample(bytes, layout.sample, layout.big_endian, |v| match v {
        Value::Int(v) if exact => layer.push_label(v),
        v => layer.push_real(v.scaled(slope, inter)),
    })
}
