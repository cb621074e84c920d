//! Binary PLY bodies, either byte order. The common layouts (float x y z only; faces as a single
//! `uchar int` list) take bulk fast paths; anything else walks each record property by property.
//! No per-record allocation; every read is bounds-checked and errors carry the absolute offset.
use super::ply::{Element, Fan, Header, Property, Role, Scalar, FORMAT};
use super::{LoadError, Location};
use crate::mesh::Mesh;

/// Reads the body; `check_counts` has bounded every element count by the body's length.
pub(super) fn read<const BE: bool>(
    header: &Header,
    body: &[u8],
    vertex_count: usize,
) -> Result<Mesh, LoadError> {
    let mut r = Reader::<BE> {
        body,
        pos: 0,
        base: header.body_start,
    };
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for element in &header.elements {
        match element.role {
            Role::Vertex { xyz } => positions = r.vertices(element, xyz)?,
            Role::Face { indices } => triangles = r.faces(element, indices, vertex_count)?,
            Role::Skip => r.skip(element)?,
        }
    }
    Ok(Mesh::new(positions, triangles))
}

struct Reader<'a, const BE: bool> {
    body: &'a [u8],
    /// Next unread byte of `body`.
    pos: usize,
    /// Offset of `body` in the file, for error messages.
    base: usize,
}

impl<'a, const BE: bool> Reader<'a, BE> {
    fn vertices(&mut self, e: &Element, xyz: [usize; 3]) -> Result<Vec<[f32; 3]>, LoadError> {
        // `check_counts` bounded count * min_size by the remaining bytes, so this fits.
        let count = e.count as usize;
        if e.properties.iter().any(|p| matches!(p, Property::List(..))) {
            let mut positions = Vec::with_capacity(count);
            for _ in 0..count {
                positions.push(self.vertex_walk(e, xyz)?);
            }
            return Ok(positions);
        }
        let stride = e.min_size();
        let start = self.pos;
        let data = self.take(count * stride, "vertex data")?;
        let all_f32 = xyz.map(|k| e.properties.get(k) == Some(&Property::Scalar(Scalar::F32)));
        let positions: Vec<[f32; 3]> = if stride == 12 && xyz == [0, 1, 2] && all_f32 == [true; 3] {
            data.chunks_exact(12)
                .map(|r| [f32_at::<BE>(r, 0), f32_at::<BE>(r, 4), f32_at::<BE>(r, 8)])
                .collect()
        } else {
            let layout = xyz.map(|k| {
                let offset: usize = e.properties[..k].iter().map(|p| p.min_size()).sum();
                let ty = match e.properties[k] {
                    Property::Scalar(t) | Property::List(t, _) => t,
                };
                (offset, ty)
            });
            data.chunks_exact(stride)
                .map(|r| layout.map(|(at, ty)| float::<BE>(ty, r, at).unwrap_or(f64::NAN) as f32))
                .collect()
        };
        // A separate pass keeps the conversion loop branch-free; errors are rare.
        if let Some((i, k)) = first_non_finite(&positions) {
            let (at, value) = self.describe_coordinate(e, xyz[k], start + i * stride);
            return Err(non_finite(self.base + at, value));
        }
        Ok(positions)
    }

    /// The offset and the stored value of property `k` of the fixed-size record at `record`.
    fn describe_coordinate(&self, e: &Element, k: usize, record: usize) -> (usize, String) {
        let at = record
            + e.properties[..k]
                .iter()
                .map(|p| p.min_size())
                .sum::<usize>();
        let value = match e.properties.get(k) {
            Some(&Property::Scalar(ty)) => float::<BE>(ty, self.body, at),
            _ => None,
        };
        (at, value.map_or_else(|| "?".into(), |v| format!("{v:?}")))
    }

    /// One vertex record with list properties among its scalars.
    fn vertex_walk(&mut self, e: &Element, xyz: [usize; 3]) -> Result<[f32; 3], LoadError> {
        let mut p = [0f32; 3];
        for (k, property) in e.properties.iter().enumerate() {
            match *property {
                Property::Scalar(ty) => {
                    let at = self.pos;
                    let raw = self.take(ty.size(), "a vertex property")?;
                    if let Some(axis) = xyz.iter().position(|&a| a == k) {
                        let value = float::<BE>(ty, raw, 0).unwrap_or(f64::NAN);
                        p[axis] = value as f32;
                        if !p[axis].is_finite() {
                            return Err(non_finite(self.base + at, format!("{value:?}")));
                        }
                    }
                }
                Property::List(count_ty, item) => self.skip_list(count_ty, item)?,
            }
        }
        Ok(p)
    }

    fn faces(
        &mut self,
        e: &Element,
        list_at: usize,
        vertex_count: usize,
    ) -> Result<Vec<[u32; 3]>, LoadError> {
        let count = e.count as usize;
        let (count_ty, item) = match e.properties.get(list_at) {
            Some(&Property::List(c, i)) => (c, i),
            _ => return Ok(Vec::new()),
        };
        // Most faces are triangles: reserve for that, bounded by what the bytes can hold.
        let triangle_size = count_ty.size() + 3 * item.size();
        let remaining = self.body.len() - self.pos;
        let mut triangles = Vec::with_capacity(count.min(remaining / triangle_size));
        let single_list = e.properties.len() == 1;
        if single_list && count_ty == Scalar::U8 && matches!(item, Scalar::I32 | Scalar::U32) {
            self.faces_u8_i32(count, item, vertex_count, &mut triangles)?;
            return Ok(triangles);
        }
        for _ in 0..count {
            for (k, property) in e.properties.iter().enumerate() {
                match *property {
                    Property::List(c, i) if k == list_at => {
                        self.face_list(c, i, vertex_count, &mut triangles)?
                    }
                    Property::List(c, i) => self.skip_list(c, i)?,
                    Property::Scalar(ty) => {
                        self.take(ty.size(), "a face property")?;
                    }
                }
            }
        }
        Ok(triangles)
    }

    /// The hot path: `property list uchar int vertex_indices` and nothing else.
    fn faces_u8_i32(
        &mut self,
        count: usize,
        item: Scalar,
        vertex_count: usize,
        triangles: &mut Vec<[u32; 3]>,
    ) -> Result<(), LoadError> {
        let body = self.body;
        let limit = vertex_count as u32;
        let mut pos = self.pos;
        for _ in 0..count {
            match body.get(pos..pos + 13) {
                Some(rec) if rec[0] == 3 => {
                    let t = [
                        u32_at::<BE>(rec, 1),
                        u32_at::<BE>(rec, 5),
                        u32_at::<BE>(rec, 9),
                    ];
                    // Negative i32 indices read as huge u32 and fail this test too.
                    if t.iter().all(|&v| v < limit) {
                        triangles.push(t);
                        pos += 13;
                        continue;
                    }
                }
                _ => {}
            }
            // Polygons, a short tail or a bad index: the general reader handles and reports it.
            self.pos = pos;
            self.face_list(Scalar::U8, item, vertex_count, triangles)?;
            pos = self.pos;
        }
        self.pos = pos;
        Ok(())
    }

    /// One index list, fan-triangulated, every index checked.
    fn face_list(
        &mut self,
        count_ty: Scalar,
        item: Scalar,
        vertex_count: usize,
        triangles: &mut Vec<[u32; 3]>,
    ) -> Result<(), LoadError> {
        let at = self.pos;
        let n = self.list_length(count_ty)?;
        if n < 3 {
            return Err(LoadError::Syntax {
                format: FORMAT,
                location: Location::Byte(self.base + at),
                detail: format!("a face needs at least 3 vertices, this one has {n}"),
            });
        }
        let mut fan = Fan::new();
        for _ in 0..n {
            let at = self.pos;
            let raw = self.take(item.size(), "a face index")?;
            let index = int::<BE>(item, raw, 0).unwrap_or(-1);
            if index < 0 || index as u64 >= vertex_count as u64 {
                return Err(LoadError::IndexOutOfRange {
                    format: FORMAT,
                    location: Location::Byte(self.base + at),
                    index,
                    count: vertex_count,
                });
            }
            fan.push(index as u32, triangles);
        }
        Ok(())
    }

    fn skip(&mut self, e: &Element) -> Result<(), LoadError> {
        if e.properties
            .iter()
            .all(|p| matches!(p, Property::Scalar(_)))
        {
            // Fixed-size records: one bounds check (count * size was checked already).
            self.take(e.count as usize * e.min_size(), "element data")?;
            return Ok(());
        }
        for _ in 0..e.count {
            for property in &e.properties {
                match *property {
                    Property::Scalar(ty) => {
                        self.take(ty.size(), "element data")?;
                    }
                    Property::List(c, i) => self.skip_list(c, i)?,
                }
            }
        }
        Ok(())
    }

    fn skip_list(&mut self, count_ty: Scalar, item: Scalar) -> Result<(), LoadError> {
        let n = self.list_length(count_ty)?;
        let bytes = n
            .checked_mul(item.size())
            .ok_or_else(|| self.truncated("list items"))?;
        self.take(bytes, "list items")?;
        Ok(())
    }

    fn list_length(&mut self, count_ty: Scalar) -> Result<usize, LoadError> {
        let at = self.pos;
        let raw = self.take(count_ty.size(), "a list length")?;
        let n = int::<BE>(count_ty, raw, 0).unwrap_or(-1);
        usize::try_from(n).map_err(|_| LoadError::Syntax {
            format: FORMAT,
            location: Location::Byte(self.base + at),
            detail: format!("negative list length {n}"),
        })
    }

    /// The next `n` bytes, or a truncation error naming what was being read.
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], LoadError> {
        let body = self.body;
        let slice = self
            .pos
            .checked_add(n)
            .and_then(|end| body.get(self.pos..end))
            .ok_or_else(|| self.truncated(what))?;
        self.pos += n;
        Ok(slice)
    }

    fn truncated(&self, what: &str) -> LoadError {
        LoadError::Truncated {
            format: FORMAT,
            offset: self.base + self.body.len(),
            detail: format!("{what} at byte {} runs past the end", self.base + self.pos),
        }
    }
}

fn non_finite(offset: usize, value: String) -> LoadError {
    LoadError::NonFinite {
        format: FORMAT,
        location: Location::Byte(offset),
        value,
    }
}

fn first_non_finite(positions: &[[f32; 3]]) -> Option<(usize, usize)> {
    let i = positions
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))?;
    let k = positions.get(i)?.iter().position(|c| !c.is_finite())?;
    Some((i, k))
}

fn bytes_at<const N: usize>(b: &[u8], at: usize) -> Option<[u8; N]> {
    b.get(at..at.checked_add(N)?)?.try_into().ok()
}

/// Callers pass a slice known to hold 4 bytes at `at` (fixed-size records).
#[inline]
fn f32_at<const BE: bool>(b: &[u8], at: usize) -> f32 {
    f32::from_bits(u32_at::<BE>(b, at))
}

#[inline]
fn u32_at<const BE: bool>(b: &[u8], at: usize) -> u32 {
    u32_opt::<BE>(b, at).unwrap_or_default()
}

#[inline]
fn u32_opt<const BE: bool>(b: &[u8], at: usize) -> Option<u32> {
    let v = bytes_at::<4>(b, at)?;
    Some(if BE {
        u32::from_be_bytes(v)
    } else {
        u32::from_le_bytes(v)
    })
}

/// A scalar of any type as f64 (`None` past the end of `b`).
fn float<const BE: bool>(ty: Scalar, b: &[u8], at: usize) -> Option<f64> {
    Some(match ty {
        Scalar::F32 => f32::from_bits(u32_opt::<BE>(b, at)?) as f64,
        Scalar::F64 => {
            let v = bytes_at::<8>(b, at)?;
            f64::from_bits(if BE {
                u64::from_be_bytes(v)
            } else {
                u64::from_le_bytes(v)
            })
        }
        _ => int::<BE>(ty, b, at)? as f64,
    })
}

/// An integer scalar as i64 (`None` past the end of `b`; floats are truncated).
fn int<const BE: bool>(ty: Scalar, b: &[u8], at: usize) -> Option<i64> {
    Some(match ty {
        Scalar::I8 => i64::from(bytes_at::<1>(b, at)?[0] as i8),
        Scalar::U8 => i64::from(bytes_at::<1>(b, at)?[0]),
        Scalar::I16 | Scalar::U16 => {
            let v = bytes_at::<2>(b, at)?;
            let u = if BE {
                u16::from_be_bytes(v)
            } else {
                u16::from_le_bytes(v)
            };
            if ty == Scalar::I16 {
                i64::from(u as i16)
            } else {
                i64::from(u)
            }
        }
        Scalar::I32 | Scalar::U32 => {
            let u = u32_opt::<BE>(b, at)?;
            if ty == Scalar::I32 {
                i64::from(u as i32)
            } else {
                i64::from(u)
            }
        }
        Scalar::F32 | Scalar::F64 => float::<BE>(ty, b, at)? as i64,
    })
}
