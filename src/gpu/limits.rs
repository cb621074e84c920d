//! Whether a mesh fits the device's limits (by default WebGPU's: 128 MiB per storage binding,
//! 256 MiB per buffer, 65,535 workgroups per dimension), checked before anything is uploaded
//! so that a too-large mesh gets an error naming the limit instead of a device error.

use super::layout::{dispatch_size, WORKGROUP_SIZE};
use super::GpuError;

/// Bytes per vertex position on the GPU (vec4<f32>: WGSL's vec3 arrays are padded to 16 anyway).
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
    for (what, bytes) in arrays {
        if bytes > limits.max_storage_buffer_binding_size {
            return Err(too_large(
                what,
                "max_storage_buffer_binding_size",
                bytes,
                limits.max_storage_buffer_binding_size,
            ));
        }
        if bytes > limits.max_buffer_size {
            return Err(too_large(
                what,
                "max_buffer_size",
                bytes,
                limits.max_buffer_size,
            ));
        }
    }
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
}
