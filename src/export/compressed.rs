//! The compressed case glTF's meshes: positions, normals and the original (morph target)
//! quantized as `KHR_mesh_quantization` allows, every array then compressed with
//! `EXT_meshopt_compression`.
//!
//! Positions are 16-bit integers on a lattice per structure: the stored `q` is at
//! `offset + step * q` millimetres, a translation and uniform scale on the structure's node, so
//! the root keeps the frame's conversion alone. The step is a power of two and the offset a
//! multiple of it, so the lattice's points are exact in f32 and a reopened case, quantized
//! again, lands on the same points. A structure extracted from voxels gets the coarsest such
//! lattice within a small part of its voxel diagonal; others the finest that 16 bits cover.
//! The original is stored as integer steps from the surface on the same lattice, so it is
//! exactly its lattice point too. Normals are 8-bit normalized. The morph target carries no
//! normals: a staircase's normals, as differences from smooth ones, took more than a fifth of
//! the file, and viewers that slide to it (ours) light it from its positions; the uncompressed
//! file keeps them. `_LOCAL_ERROR` stays float.

use serde_json::{json, Value};

use super::glb::{Builder, FLOAT, TRIANGLES};
use super::meshopt::codec_order;
use super::ExportError;
use crate::mesh::Mesh;

const BYTE: u32 = 5120;
const SHORT: u32 = 5122;
const UNSIGNED_SHORT: u32 = 5123;
/// The largest stored position value (16 bits).
const Q_MAX: f64 = 65535.0;
/// The largest quantization error a structure extracted from voxels allows, in its voxel
/// diagonals: far below what smoothing moves, and coarse lattices compress better.
const LATTICE_ERROR_VOXEL_DIAGONALS: f64 = 0.04;
/// Normals' scale: 8-bit signed normalized.
const NORMAL_MAX: f32 = 127.0;

/// A structure's position lattice: stored `q` is at `offset + step * q` mm on each axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Lattice {
    pub offset: [f32; 3],
    pub step: f32,
}

impl Lattice {
    /// The coarsest power-of-two lattice whose steps are at most `max_step` mm (when given),
    /// or the finest one whose 16-bit range covers `points` where that is coarser.
    pub(super) fn covering<'a>(
        points: impl Iterator<Item = &'a [f32; 3]> + Clone,
        max_step: Option<f64>,
    ) -> Lattice {
        let mut min = [f64::INFINITY; 3];
        let mut max = [f64::NEG_INFINITY; 3];
        for p in points {
            for k in 0..3 {
                min[k] = min[k].min(f64::from(p[k]));
                max[k] = max[k].max(f64::from(p[k]));
            }
        }
        let extent = (0..3).map(|k| max[k] - min[k]).fold(0.0, f64::max);
        // A point (or nothing) still gets a lattice; -40 keeps the step a normal f32.
        let mut exponent = (extent / Q_MAX).log2().ceil().max(-40.0) as i32;
        if let Some(coarsest) = max_step.filter(|s| s.is_finite() && *s > 0.0) {
            exponent = exponent.max(coarsest.log2().floor().clamp(-40.0, 40.0) as i32);
        }
        loop {
            let step = 2f64.powi(exponent);
            let offset = min.map(|m| ((m / step).floor() * step) as f32);
            let fits = (0..3).all(|k| {
                let (lo, hi) = (min[k] - f64::from(offset[k]), max[k] - f64::from(offset[k]));
                lo >= -0.5 * step && hi <= (Q_MAX + 0.5) * step
            });
            // Rounding the offset to f32 can shift it by more than a step far from the origin:
            // a coarser lattice then fits.
            if fits || exponent > 120 {
                return Lattice {
                    offset,
                    step: step as f32,
                };
            }
            exponent += 1;
        }
    }

    pub(super) fn quantize(&self, p: [f32; 3]) -> [u16; 3] {
        std::array::from_fn(|k| {
            let q = (f64::from(p[k]) - f64::from(self.offset[k])) / f64::from(self.step);
            q.round().clamp(0.0, Q_MAX) as u16
        })
    }

    /// Where stored `q` lies, computed as a reader applying the node's transform does (in f64,
    /// rounded once to f32).
    pub(super) fn position(&self, q: [f64; 3]) -> [f32; 3] {
        std::array::from_fn(|k| (f64::from(self.step) * q[k] + f64::from(self.offset[k])) as f32)
    }
}

fn distance(a: [f32; 3], b: [f32; 3]) -> f64 {
    (0..3)
        .map(|k| (f64::from(a[k]) - f64::from(b[k])).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Stored positions (stride 8: three u16 and a pad) and the largest distance (mm) from a
/// point to where it is stored.
fn quantized_positions(lattice: &Lattice, points: &[[f32; 3]]) -> (Vec<[u16; 3]>, f64) {
    let mut worst = 0.0f64;
    let q: Vec<[u16; 3]> = points
        .iter()
        .map(|&p| {
            let q = lattice.quantize(p);
            worst = worst.max(distance(lattice.position(q.map(f64::from)), p));
            q
        })
        .collect();
    (q, worst)
}

fn padded<const N: usize, T: Copy>(
    values: &[[T; N]],
    pad: T,
    bytes: impl Fn(T) -> Vec<u8>,
) -> Vec<u8> {
    values
        .iter()
        .flat_map(|v| v.iter().copied().chain(std::iter::once(pad)))
        .flat_map(bytes)
        .collect()
}

fn bounds<const N: usize, T: Copy + Into<f64>>(values: &[[T; N]]) -> (Vec<f64>, Vec<f64>) {
    let mut min = vec![f64::INFINITY; N];
    let mut max = vec![f64::NEG_INFINITY; N];
    for v in values {
        for k in 0..N {
            min[k] = min[k].min(v[k].into());
            max[k] = max[k].max(v[k].into());
        }
    }
    (min, max)
}

/// A unit normal as `EXT_meshopt_compression`'s octahedral filter stores it in 8 bits: its
/// point on the octahedron |x| + |y| + |z| = 1 as x and y, the lower half folded over the
/// upper, and 1.0 in z. Two numbers where xyz takes three compress better, as precisely.
fn octahedral(n: [f32; 3]) -> [i8; 4] {
    let l1 = n[0].abs() + n[1].abs() + n[2].abs();
    if l1.is_nan() || l1 <= 0.0 {
        return [0, 0, NORMAL_MAX as i8, 0];
    }
    let (mut u, mut v) = (n[0] / l1, n[1] / l1);
    if n[2] < 0.0 {
        let sign = |x: f32| if x >= 0.0 { 1.0 } else { -1.0 };
        (u, v) = ((1.0 - v.abs()) * sign(u), (1.0 - u.abs()) * sign(v));
    }
    let q = |x: f32| (x * NORMAL_MAX).round().clamp(-NORMAL_MAX, NORMAL_MAX) as i8;
    [q(u), q(v), NORMAL_MAX as i8, 0]
}

/// What the compressed mesh of a structure adds to its node: the lattice (as the node's
/// translation and scale) and the quantization record.
pub(super) struct Placement {
    pub lattice: Lattice,
    pub record: Value,
}

/// The surfaces of one structure, as [`structure_mesh`] writes them.
pub(super) struct Surfaces<'a> {
    pub shown: &'a Mesh,
    pub normals: &'a [[f32; 3]],
    /// The original, where it rides along as the morph target.
    pub original: Option<&'a Mesh>,
    pub local_error: Option<&'a [f32]>,
    pub voxel_diagonal: Option<f64>,
}

/// A structure's primitive, quantized and compressed: its attributes, indices and morph target,
/// with vertices and triangles in the order the codecs compress best.
pub(super) fn structure_mesh(
    b: &mut Builder,
    s: &Surfaces,
    material: usize,
) -> Result<(Value, Placement), ExportError> {
    let (triangles, old_of_new) = codec_order(&s.shown.triangles, s.shown.positions.len());
    let pick =
        |v: &[[f32; 3]]| -> Vec<[f32; 3]> { old_of_new.iter().map(|&i| v[i as usize]).collect() };
    let shown = Mesh::new(pick(&s.shown.positions), triangles);
    let normals = pick(s.normals);
    let original = s
        .original
        .map(|o| Mesh::new(pick(&o.positions), shown.triangles.clone()));
    let local_error: Option<Vec<f32>> = s
        .local_error
        .map(|e| old_of_new.iter().map(|&i| e[i as usize]).collect());
    let ordered = Surfaces {
        shown: &shown,
        normals: &normals,
        original: original.as_ref(),
        local_error: local_error.as_deref(),
        voxel_diagonal: s.voxel_diagonal,
    };
    ordered_mesh(b, &ordered, material)
}

fn ordered_mesh(
    b: &mut Builder,
    s: &Surfaces,
    material: usize,
) -> Result<(Value, Placement), ExportError> {
    let shown = &s.shown.positions;
    // A point lies within half a step on each axis of its lattice point.
    let max_step =
        (s.voxel_diagonal).map(|d| 2.0 * LATTICE_ERROR_VOXEL_DIAGONALS * d / 3f64.sqrt());
    let lattice = match s.original {
        Some(o) => Lattice::covering(shown.iter().chain(&o.positions), max_step),
        None => Lattice::covering(shown.iter(), max_step),
    };
    let (q, mut worst) = quantized_positions(&lattice, shown);
    let n = q.len();
    let (min, max) = bounds(&q);
    let position = b.push_attributes(
        &padded(&q, 0u16, |v| v.to_le_bytes().to_vec()),
        8,
        json!({"componentType": UNSIGNED_SHORT, "count": n, "type": "VEC3", "min": min, "max": max}),
    )?;
    let normals: Vec<[i8; 4]> = (super::glb::unit_normals(s.normals).into_iter())
        .map(octahedral)
        .collect();
    let normal = b.push_filtered_attributes(
        &normals
            .iter()
            .flatten()
            .map(|v| v.to_le_bytes()[0])
            .collect::<Vec<u8>>(),
        4,
        json!({"componentType": BYTE, "normalized": true, "count": n, "type": "VEC3"}),
        "OCTAHEDRAL",
    )?;
    let mut attributes = json!({ "POSITION": position, "NORMAL": normal });
    if let Some(errors) = s.local_error {
        let bytes: Vec<u8> = errors.iter().flat_map(|v| v.to_le_bytes()).collect();
        attributes["_LOCAL_ERROR"] = json!(b.push_attributes(
            &bytes,
            4,
            json!({"componentType": FLOAT, "count": n, "type": "SCALAR"}),
        )?);
    }
    let triangles: Vec<u32> = s.shown.triangles.iter().flatten().copied().collect();
    let indices = b.push_triangles(&triangles, n)?;
    let mut primitive = json!({
        "attributes": attributes, "indices": indices, "material": material, "mode": TRIANGLES,
    });
    if let Some(original) = s.original {
        let (target, original_worst) = morph_target(b, &lattice, &q, original)?;
        worst = worst.max(original_worst);
        primitive["targets"] = json!([target]);
    }
    let record = json!({
        "position_bits": 16,
        "step_mm": lattice.step,
        "max_error_mm": worst,
        "max_error_voxel_diagonals": s.voxel_diagonal.map(|d| worst / d),
        "normal_bits": 8,
    });
    Ok((primitive, Placement { lattice, record }))
}

/// The original on the surface's lattice, as integer steps from the surface, with its largest
/// quantization error (mm).
fn morph_target(
    b: &mut Builder,
    lattice: &Lattice,
    shown: &[[u16; 3]],
    original: &Mesh,
) -> Result<(Value, f64), ExportError> {
    let (q, worst) = quantized_positions(lattice, &original.positions);
    let steps: Vec<[i32; 3]> = (q.iter().zip(shown))
        .map(|(o, s)| std::array::from_fn(|k| i32::from(o[k]) - i32::from(s[k])))
        .collect();
    let (min, max) = bounds(&steps);
    let count = steps.len();
    let short = steps.iter().flatten().all(|&d| i16::try_from(d).is_ok());
    let position = if short {
        b.push_attributes(
            &padded(&steps, 0, |v| (v as i16).to_le_bytes().to_vec()),
            8,
            json!({"componentType": SHORT, "count": count, "type": "VEC3", "min": min, "max": max}),
        )?
    } else {
        // Steps past 16 bits (an original far from its surface) are exact as floats too.
        let floats: Vec<[f32; 3]> = steps.iter().map(|v| v.map(|d| d as f32)).collect();
        b.push_attributes(
            &super::glb::floats(&floats),
            12,
            json!({"componentType": FLOAT, "count": count, "type": "VEC3", "min": min, "max": max}),
        )?
    };
    Ok((json!({ "POSITION": position }), worst))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lattice_covers_the_points_within_half_a_step() {
        let points = [[-12.3, 40.0, 7.25], [88.1, 41.5, 9.0], [0.0, 120.7, -3.0]];
        let l = Lattice::covering(points.iter(), None);
        assert!(l.step.log2().fract() == 0.0, "a power of two: {}", l.step);
        // The extent is 100.4 mm (x): 2^-9 mm steps are the finest whose 65535 hold it.
        assert_eq!(l.step, 2f32.powi(-9));
        for p in points {
            let back = l.position(l.quantize(p).map(f64::from));
            assert!(distance(back, p) <= 0.5 * f64::from(l.step) * 3f64.sqrt());
            // Quantizing a lattice point again gives the same point.
            assert_eq!(l.position(l.quantize(back).map(f64::from)), back);
        }
        let one = Lattice::covering([[5.0, 5.0, 5.0]].iter(), None);
        assert_eq!(
            one.position(one.quantize([5.0; 3]).map(f64::from)),
            [5.0; 3]
        );
    }

    #[test]
    fn octahedral_normals_decode_within_a_degree_and_a_half() {
        use meshopt_rs::vertex::filter::decode_filter_oct_8;
        let mut worst = 0.0f32;
        for i in 0..2000 {
            // A spiral over the sphere, both halves, and the axes.
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / 2000.0;
            let r = (1.0 - z * z).sqrt();
            let a = i as f32 * 2.399_963;
            for n in [
                [r * a.cos(), r * a.sin(), z],
                [0.0, 0.0, -1.0],
                [-1.0, 0.0, 0.0],
            ] {
                let mut stored = [octahedral(n).map(|v| v.to_le_bytes()[0])];
                decode_filter_oct_8(&mut stored);
                let back: [f32; 3] = std::array::from_fn(|k| f32::from(stored[0][k] as i8) / 127.0);
                let l = back.iter().map(|v| v * v).sum::<f32>().sqrt();
                let cos = (0..3).map(|k| back[k] * n[k]).sum::<f32>() / l;
                worst = worst.max(cos.clamp(-1.0, 1.0).acos().to_degrees());
            }
        }
        assert!(worst < 1.5, "{worst} degrees");
    }
}
