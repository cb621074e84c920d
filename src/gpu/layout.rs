//! What the Rust side and the WGSL side must agree on: the step-parameter record, its slots in
//! the uniform buffer, and the workgroup grid.

use bytemuck::{Pod, Zeroable};

/// Threads per workgroup; must equal `WORKGROUP_SIZE` in shaders/mesh.wgsl (checked by a test).
pub const WORKGROUP_SIZE: u32 = 64;

/// Flags of [`StepParams::flags`], as in shaders/mesh.wgsl.
pub(crate) const HAS_WEIGHTS: u32 = 1;
pub(crate) const HAS_BOUND: u32 = 2;

/// One step's parameters, `StepParams` in shaders/mesh.wgsl: std140-compatible (the vec4
/// starts at byte 32, a multiple of 16), 48 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct StepParams {
    pub vertex_count: u32,
    pub flags: u32,
    pub bound: f32,
    pub factor: f32,
    pub alpha: f32,
    pub beta: f32,
    pub c0: f32,
    pub c1: f32,
    pub centre: [f32; 4],
}

const _: () = assert!(std::mem::size_of::<StepParams>() == 48);
const _: () = assert!(std::mem::offset_of!(StepParams, centre) == 32);

/// Per-mesh constants of the surface kernels (drift, normals, measures), `SurfaceParams` in
/// shaders/surface.wgsl: 32 bytes, the vec4 at byte 16.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct SurfaceParams {
    pub vertex_count: u32,
    pub pad: [u32; 3],
    /// The original bounding box's centre (w = 0): the measures sum the volume about it.
    pub centre: [f32; 4],
}

const _: () = assert!(std::mem::size_of::<SurfaceParams>() == 32);
const _: () = assert!(std::mem::offset_of!(SurfaceParams, centre) == 16);

/// One workgroup's sums of a measure pass, `Partial` in shaders/measure.wgsl: 32 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct MeasurePartial {
    pub error_sum: f32,
    pub error_max: f32,
    pub curvature_sum: f32,
    /// Six times the volume of the triangles whose smallest corner is in the workgroup.
    pub volume6: f32,
    pub error_count: u32,
    pub curvature_count: u32,
    /// The workgroup's share of the roughness R ([`crate::metrics::roughness()`]).
    pub roughness: f32,
    pub pad: u32,
}

const _: () = assert!(std::mem::size_of::<MeasurePartial>() == 32);

/// Which workgroups one part of a measure pass covers, `MeasurePart` in shaders/measure.wgsl
/// (16 bytes): the pass runs as parts, each a 1-D dispatch of its own, so a caller may spread
/// one measure over several submissions (a frame each in the browser).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub(crate) struct MeasurePart {
    pub first_group: u32,
    pub group_count: u32,
    pub pad: [u32; 2],
}

const _: () = assert!(std::mem::size_of::<MeasurePart>() == 16);

/// How many parts a measure pass has at most: small enough pieces for a slow (software)
/// adapter's frame, few enough that recording them all costs nothing.
pub(crate) const MEASURE_PARTS: u32 = 16;

/// The parts of a measure pass over `vertex_count` vertices: consecutive runs of whole
/// workgroups, at most [`MEASURE_PARTS`] of them (more only where a part would exceed
/// `max_per_dimension` workgroups), covering every workgroup once.
pub(crate) fn measure_parts(vertex_count: u32, max_per_dimension: u32) -> Vec<MeasurePart> {
    let groups = vertex_count.div_ceil(WORKGROUP_SIZE);
    let per_part = groups
        .div_ceil(MEASURE_PARTS)
        .clamp(1, max_per_dimension.max(1));
    (0..groups)
        .step_by(per_part as usize)
        .map(|first_group| MeasurePart {
            first_group,
            group_count: per_part.min(groups - first_group),
            pad: [0; 2],
        })
        .collect()
}

/// Step records a run may need at once: windowed sinc's one per term after the first, up to its
/// largest valid iteration count (100); the other filters use one or two.
pub(crate) const MAX_STEP_SLOTS: usize = 100;

/// Distance between step records in the uniform buffer: each is bound at a dynamic offset,
/// which must be a multiple of the device's `min_uniform_buffer_offset_alignment`.
pub(crate) fn step_stride(min_uniform_buffer_offset_alignment: u32) -> u64 {
    record_stride::<StepParams>(min_uniform_buffer_offset_alignment)
}

/// Distance between records of type `T` bound at dynamic offsets of a uniform buffer.
pub(crate) fn record_stride<T>(min_uniform_buffer_offset_alignment: u32) -> u64 {
    let align = u64::from(min_uniform_buffer_offset_alignment.max(1));
    (std::mem::size_of::<T>() as u64).div_ceil(align) * align
}

/// Workgroups `(x, y)` covering `vertex_count` vertices: one row while it fits in
/// `max_per_dimension`, then rows of `max_per_dimension` (the kernels index
/// `x + y * groups.x * WORKGROUP_SIZE` and skip indices past the vertex count). `None` when
/// even a square grid is too small.
pub(crate) fn dispatch_size(vertex_count: u32, max_per_dimension: u32) -> Option<(u32, u32)> {
    let groups = vertex_count.div_ceil(WORKGROUP_SIZE);
    let max = max_per_dimension.max(1);
    if groups <= max {
        return Some((groups, 1));
    }
    let rows = groups.div_ceil(max);
    (rows <= max).then_some((max, rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_covers_every_vertex_once_within_the_limit() {
        assert_eq!(dispatch_size(0, 65_535), Some((0, 1)));
        assert_eq!(dispatch_size(1, 65_535), Some((1, 1)));
        assert_eq!(dispatch_size(64 * 65_535, 65_535), Some((65_535, 1)));
        assert_eq!(dispatch_size(64 * 65_535 + 1, 65_535), Some((65_535, 2)));
        for (n, max) in [(1000u32, 4u32), (64 * 16, 4), (64 * 16 + 1, 4), (300, 1)] {
            match dispatch_size(n, max) {
                Some((x, y)) => {
                    assert!(x <= max && y <= max);
                    assert!(u64::from(x) * u64::from(y) * 64 >= u64::from(n));
                    // Not a whole row more than needed.
                    assert!(u64::from(x) * u64::from(y - 1) * 64 < u64::from(n.max(1)));
                }
                None => assert!(u64::from(n) > u64::from(max * max) * 64, "n {n} max {max}"),
            }
        }
        assert_eq!(dispatch_size(64 * 16 + 1, 4), None);
    }

    #[test]
    fn measure_parts_cover_every_workgroup_once() {
        assert!(measure_parts(0, 65_535).is_empty());
        for (n, max) in [
            (1u32, 65_535u32),
            (64, 65_535),
            (2_296, 65_535),
            (206_512, 65_535),
            (64 * 40, 3),
            (10_000_000, 65_535),
        ] {
            let parts = measure_parts(n, max);
            let mut next = 0;
            for part in &parts {
                assert_eq!(part.first_group, next, "n {n}");
                assert!(part.group_count >= 1 && part.group_count <= max, "n {n}");
                next += part.group_count;
            }
            assert_eq!(next, n.div_ceil(64), "n {n}");
            if n.div_ceil(64) <= MEASURE_PARTS * max {
                assert!(
                    parts.len() as u32 <= MEASURE_PARTS,
                    "n {n}: {} parts",
                    parts.len()
                );
            }
        }
        // Far past one part per workgroup: more parts rather than a dispatch over the limit.
        assert_eq!(measure_parts(64 * 40, 2).len(), 20);
    }

    #[test]
    fn stride_respects_the_alignment() {
        assert_eq!(step_stride(256), 256);
        assert_eq!(step_stride(16), 48);
        assert_eq!(step_stride(32), 64);
    }
}
