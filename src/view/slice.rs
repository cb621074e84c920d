//! The image's slice on the clipping plane, as radiology viewers show it: what the renderer
//! uploads (the grey levels as a 3D texture, no larger along any side than the GPU takes) and
//! the per-frame record of where the slice lies (`Slice` in shaders/render.wgsl).

use std::borrow::Cow;

use bytemuck::{Pod, Zeroable};
use glam::{DMat4, DVec4, Vec3};

use crate::case::CaseImage;
use crate::io::{reduced_affine, Affine, BlockMeans};

/// `Slice` in shaders/render.wgsl, 128 bytes.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct SliceUniforms {
    /// World millimetres to texture coordinates (0 and 1 at the grid's outer faces),
    /// column-major.
    pub world_to_texture: [[f32; 4]; 4],
    /// The quad the slice is drawn on: the plane across the image's box, w = 1.
    pub corners: [[f32; 4]; 4],
}

const _: () = assert!(std::mem::size_of::<SliceUniforms>() == 128);

/// The image as a texture: its grid (reduced to fit), grey levels, and where it lies.
pub struct SliceTexture<'a> {
    pub dims: [usize; 3],
    pub voxels: Cow<'a, [u8]>,
    pub placement: SlicePlacement,
}

/// Where a texture of the image lies in the world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlicePlacement {
    world_to_texture: DMat4,
    /// The box its voxels' outer faces span in world space.
    min: Vec3,
    max: Vec3,
}

impl<'a> SliceTexture<'a> {
    /// `image`, reduced by the smallest whole factor that leaves no side past `max_side`;
    /// `None` when the reduced texture's memory cannot be had.
    pub fn new(image: &'a CaseImage, max_side: usize) -> Option<Self> {
        let longest = image.dims.iter().copied().max().unwrap_or(1);
        let factor = longest.div_ceil(max_side.max(1)).max(1);
        let (dims, voxels, affine) = if factor == 1 {
            (image.dims, Cow::Borrowed(&image.voxels[..]), image.affine)
        } else {
            let (dims, voxels) = block_means(image.dims, &image.voxels, factor)?;
            (
                dims,
                Cow::Owned(voxels),
                reduced_affine(&image.affine, factor),
            )
        };
        let index_to_world = affine_matrix(&affine);
        // Texture coordinate = (index + 0.5) / dims.
        let size = glam::DVec3::from_array(dims.map(|d| d as f64));
        let index_to_texture =
            DMat4::from_scale(1.0 / size) * DMat4::from_translation(glam::DVec3::splat(0.5));
        let world_to_texture = index_to_texture * index_to_world.inverse();
        let (min, max) = outer_box(&affine, dims);
        Some(SliceTexture {
            dims,
            voxels,
            placement: SlicePlacement {
                world_to_texture,
                min,
                max,
            },
        })
    }
}

impl SlicePlacement {
    /// Where the slice lies for the clipping plane `(n, d)` (`n` along a world axis, as
    /// [`super::Clip`] makes it); `None` when the plane misses the image.
    pub fn uniforms(&self, plane: [f32; 4]) -> Option<SliceUniforms> {
        let n = Vec3::new(plane[0], plane[1], plane[2]);
        let axis = (0..3).find(|&a| n[a].abs() > 0.5)?;
        let at = plane[3] / n[axis];
        if !(self.min[axis]..=self.max[axis]).contains(&at) {
            return None;
        }
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        let corner = |cu: f32, cv: f32| {
            let mut p = [0.0f32; 4];
            p[axis] = at;
            p[u] = cu;
            p[v] = cv;
            p[3] = 1.0;
            p
        };
        let (lo, hi) = (self.min, self.max);
        Some(SliceUniforms {
            world_to_texture: self.world_to_texture.as_mat4().to_cols_array_2d(),
            corners: [
                corner(lo[u], lo[v]),
                corner(hi[u], lo[v]),
                corner(hi[u], hi[v]),
                corner(lo[u], hi[v]),
            ],
        })
    }
}

/// An affine's voxel-to-world matrix.
fn affine_matrix(affine: &Affine) -> DMat4 {
    let m = &affine.0;
    DMat4::from_cols(
        DVec4::new(m[0][0], m[1][0], m[2][0], 0.0),
        DVec4::new(m[0][1], m[1][1], m[2][1], 0.0),
        DVec4::new(m[0][2], m[1][2], m[2][2], 0.0),
        DVec4::new(m[0][3], m[1][3], m[2][3], 1.0),
    )
}

/// The world box of the grid's outer faces (voxel centres +- half a voxel).
fn outer_box(affine: &Affine, dims: [usize; 3]) -> (Vec3, Vec3) {
    let mut min = Vec3::splat(f32::INFINITY);
    let mut max = Vec3::splat(f32::NEG_INFINITY);
    for corner in 0..8 {
        let index: [f64; 3] = std::array::from_fn(|a| match corner >> a & 1 {
            0 => -0.5,
            _ => dims[a] as f64 - 0.5,
        });
        let p = Vec3::from_array(affine.apply(index).map(|c| c as f32));
        min = min.min(p);
        max = max.max(p);
    }
    (min, max)
}

/// Means of `factor`-sided blocks (fewer voxels at the far ends), rounded to grey levels; `None`
/// when the memory cannot be had.
fn block_means(dims: [usize; 3], voxels: &[u8], factor: usize) -> Option<([usize; 3], Vec<u8>)> {
    let mut means = BlockMeans::new(dims, factor)?;
    for &v in voxels {
        means.push(f32::from(v));
    }
    let (out, means) = means.finish();
    Some((out, means.iter().map(|m| m.round() as u8).collect()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case::Window;

    fn image(dims: [usize; 3], affine: Affine) -> CaseImage {
        let voxels = (0..dims.iter().product::<usize>())
            .map(|v| (v % 251) as u8)
            .collect();
        CaseImage {
            source: "ct.nii.gz".into(),
            dims,
            affine,
            voxels,
            preset: "ct-soft-tissue".into(),
            window: Window {
                center: 40.0,
                width: 400.0,
            },
        }
    }

    fn to_texture(u: &SliceUniforms, world: [f32; 3]) -> Vec3 {
        let m = glam::Mat4::from_cols_array_2d(&u.world_to_texture);
        m.transform_point3(Vec3::from_array(world))
    }

    #[test]
    fn voxel_centres_map_to_texel_centres_and_the_quad_spans_the_box_on_the_plane() {
        // RAS from LPS-like axes, as a NIfTI of a CT often has.
        let affine = Affine([
            [-0.78, 0.0, 0.0, 120.0],
            [0.0, -0.78, 0.0, 95.0],
            [0.0, 0.0, 2.5, -40.0],
        ]);
        let grey = image([160, 140, 48], affine);
        let texture = SliceTexture::new(&grey, 256).expect("texture");
        assert_eq!(texture.dims, [160, 140, 48]);
        let u = texture
            .placement
            .uniforms([0.0, 0.0, 1.0, 20.0])
            .expect("inside");
        let centre = affine.apply([3.0, 7.0, 24.0]).map(|c| c as f32);
        let t = to_texture(&u, centre);
        let expected = Vec3::new(3.5 / 160.0, 7.5 / 140.0, 24.5 / 48.0);
        assert!(
            (t - expected).abs().max_element() < 1e-5,
            "{t} vs {expected}"
        );
        for c in u.corners {
            assert_eq!(c[2], 20.0);
            let t = to_texture(&u, [c[0], c[1], c[2]]);
            assert!(t.x.abs() < 1e-5 || (t.x - 1.0).abs() < 1e-5, "{t}");
            assert!(t.y.abs() < 1e-5 || (t.y - 1.0).abs() < 1e-5, "{t}");
        }
        // A flipped plane (n and d negated) is the same plane; one past the box shows none.
        assert_eq!(texture.placement.uniforms([0.0, 0.0, -1.0, -20.0]), Some(u));
        assert_eq!(texture.placement.uniforms([0.0, 0.0, 1.0, 90.0]), None);
        assert_eq!(texture.placement.uniforms([0.0; 4]), None);
    }

    #[test]
    fn a_grid_past_the_gpu_limit_is_reduced_and_stays_where_it_was() {
        let affine = Affine::scaled([1.0, 1.0, 2.0], [-10.0, 5.0, 0.0]);
        let grey = image([300, 20, 10], affine);
        let texture = SliceTexture::new(&grey, 256).expect("texture");
        assert_eq!(texture.dims, [150, 10, 5]);
        let block: usize = [0, 1, 300, 301, 6000, 6001, 6300, 6301]
            .iter()
            .map(|v| v % 251)
            .sum();
        assert_eq!(usize::from(texture.voxels[0]), (block + 4) / 8);
        let full = SliceTexture::new(&grey, 512).expect("texture");
        assert_eq!(
            (texture.placement.min, texture.placement.max),
            (full.placement.min, full.placement.max)
        );
    }
}
