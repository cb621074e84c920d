//! Whether a mesh fits the device's limits (by default WebGPU's: 128 MiB per storage binding,
//! 256 MiB per buffer, 65,535 workgroups per dimension), checked before anything is uploaded
//! so that a too-large mesh gets an error naming the limit instead of a device error.

use super::layout::{dispatch_size, MeasurePartial, WORKGROUP_SIZE};
use super::GpuError;

/// Bytes per vertex position on the GPU (`vec4<f32>`: WGSL's vec3 arrays are padded to 16 anyway).
pub(crate) const POSITION_BYTES: u64 = 16;

/// Checks that `vertex_count` vertices with `ring_entries` smoothing-ring entries fit `limits`.
pub(crate) fn check_mesh_fits(
    limits: &wgpu::Limits,
    vertex_count: usize,
    ring_entries: usize,
) -> Result<(), GpuError> {
    let too_large = |what: String, limit, needed, allowed| GpuError::TooLarge {
        what,
        limit,
        needed,
        allowed,
    };
    // Indices are u32 on the GPU; the offsets array holds vertex_count + 1 of them.
    let max_index = u64::from(u32::MAX) - 1;
    if vertex_count as u64 > max_index {
        return Err(too_large(
            format!("a mesh of {vertex_count} vertices"),
            "u32 vertex index range (vertices)",
            vertex_count as u64,
            max_index,
        ));
    }
    if ring_entries as u64 > max_index {
        return Err(too_large(
            format!("a smoothing ring of {ring_entries} entries"),
            "u32 index range (ring entries)",
            ring_entries as u64,
            max_index,
        ));
    }
    let arrays = [
        (
            format!("the positions of {vertex_count} vertices (bytes)"),
            vertex_count as u64 * POSITION_BYTES,
        ),
        (
            format!("the smoothing ring's {ring_entries} neighbour indices (bytes)"),
            ring_entries as u64 * 4,
        ),
        (
            format!("the ring offsets of {vertex_count} vertices (bytes)"),
            (vertex_count as u64 + 1) * 4,
        ),
    ];
    check_arrays(limits, arrays)?;
    let max = limits.max_compute_workgroups_per_dimension;
    if dispatch_size(vertex_count as u32, max).is_none() {
        let groups = (vertex_count as u64).div_ceil(u64::from(WORKGROUP_SIZE));
        return Err(too_large(
            format!("{vertex_count} vertices in workgroups of {WORKGROUP_SIZE} (workgroups)"),
            "max_compute_workgroups_per_dimension (squared, in a 2-D dispatch)",
            groups,
            u64::from(max) * u64::from(max),
        ));
    }
    Ok(())
}

/// Bytes per entry of the per-vertex measures (local error, K_G as `vec2<f32>`).
pub(crate) const VERTEX_MEASURE_BYTES: u64 = 8;

/// Checks that what the drift, normals and measures add to a mesh fits `limits`: the full
/// 1-ring of `ring_entries` entries, `fan_entries` vertex->triangle incidences (two corners
/// each), per-vertex arrays and `partials` workgroup sums; and that a readback of positions and
/// references together fits one buffer.
pub(crate) fn check_surface_fits(
    limits: &wgpu::Limits,
    vertex_count: usize,
    ring_entries: usize,
    fan_entries: usize,
    partials: usize,
) -> Result<(), GpuError> {
    let n = vertex_count as u64;
    if fan_entries as u64 > u64::from(u32::MAX) - 1 {
        return Err(GpuError::TooLarge {
            what: format!("{fan_entries} vertex-triangle incidences"),
            limit: "u32 index range (incidences)",
            needed: fan_entries as u64,
            allowed: u64::from(u32::MAX) - 1,
        });
    }
    check_arrays(
        limits,
        [
            (
                format!("the 1-ring's {ring_entries} neighbour indices (bytes)"),
                ring_entries as u64 * 4,
            ),
            (
                format!("the triangle corners of {fan_entries} vertex-triangle incidences (bytes)"),
                fan_entries as u64 * 8,
            ),
            (
                format!("the normals of {vertex_count} vertices (bytes)"),
                n * POSITION_BYTES,
            ),
            (
                format!("the measures of {vertex_count} vertices (bytes)"),
                n * VERTEX_MEASURE_BYTES,
            ),
            (
                format!("the sums of {partials} workgroups (bytes)"),
                partials as u64 * std::mem::size_of::<MeasurePartial>() as u64,
            ),
        ],
    )?;
    // One staging buffer for positions and references (not a binding: only the buffer limit).
    let readback = n * (POSITION_BYTES + 4);
    if readback > limits.max_buffer_size {
        return Err(GpuError::TooLarge {
            what: format!(
                "a readback of the positions and references of {vertex_count} vertices (bytes)"
            ),
            limit: "max_buffer_size",
            needed: readback,
            allowed: limits.max_buffer_size,
        });
    }
    Ok(())
}

/// Each array must fit one storage binding and one buffer.
fn check_arrays<const N: usize>(
    limits: &wgpu::Limits,
    arrays: [(String, u64); N],
) -> Result<(), GpuError> {
    for (what, bytes) in arrays {
        for (limit, allowed) in [
            (
                "max_storage_buffer_binding_size",
                limits.max_storage_buffer_binding_size,
            ),
            ("max_buffer_size", limits.max_buffer_size),
        ] {
            if bytes > allowed {
                return Err(GpuError::TooLarge {
                    what,
                    limit,
                    needed: bytes,
                    allowed,
                });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn webgpu_defaults_take_millions_of_vertices_and_refuse_more() {
        let limits = wgpu::Limits::default();
        // A 5-million-vertex mesh of valence 6 fits...
        check_mesh_fits(&limits, 5_000_000, 30_000_000).expect("fits");
        // ...but 128 MiB of vec4<f32> ends at 8,388,608 vertices.
        let e = check_mesh_fits(&limits, 8_388_609, 6).expect_err("too many vertices");
        assert!(
            matches!(
                e,
                GpuError::TooLarge {
                    limit: "max_storage_buffer_binding_size",
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("max_storage_buffer_binding_size"));
        let e = check_mesh_fits(&limits, 1000, 40_000_000).expect_err("too many ring entries");
        assert!(e.to_string().contains("neighbour indices"), "{e}");
    }

    #[test]
    fn the_workgroup_grid_is_a_limit_too() {
        let limits = wgpu::Limits {
            max_compute_workgroups_per_dimension: 10,
            ..wgpu::Limits::default()
        };
        check_mesh_fits(&limits, 6400, 0).expect("a 10 x 10 grid of 64");
        let e = check_mesh_fits(&limits, 6401, 0).expect_err("needs 101 workgroups");
        assert!(
            e.to_string()
                .contains("max_compute_workgroups_per_dimension"),
            "{e}"
        );
        let limits = wgpu::Limits {
            max_buffer_size: 1024,
            ..wgpu::Limits::default()
        };
        let e = check_mesh_fits(&limits, 100, 0).expect_err("1600 bytes of positions");
        assert!(e.to_string().contains("max_buffer_size"), "{e}");
    }

    #[test]
    fn the_measures_have_limits_of_their_own() {
        let limits = wgpu::Limits::default();
        // 2 million vertices of valence 6: 12 million incidences, 96 MB of corners.
        check_surface_fits(&limits, 2_000_000, 12_000_000, 12_000_000, 31_250).expect("fits");
        // 5 million vertices fit the smoothing but not the fans' 240 MB of corners.
        check_mesh_fits(&limits, 5_000_000, 30_000_000).expect("smoothing fits");
        let e = check_surface_fits(&limits, 5_000_000, 30_000_000, 30_000_000, 78_125)
            .expect_err("fans too large");
        assert!(e.to_string().contains("incidences"), "{e}");
        assert!(
            e.to_string().contains("max_storage_buffer_binding_size"),
            "{e}"
        );
    }
}
