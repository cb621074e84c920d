//! Thumbnails on the CPU: a mesh drawn the way the 3D view draws it (same camera matrices, same
//! lights and colours as shaders/render.wgsl), small, for a gallery of results that should not
//! each need a GPU render target.
//!
//! Visibility first, shading after: every triangle is rasterised into a depth buffer that keeps
//! the nearest triangle per sample, then only the samples that show a triangle are shaded. At
//! thumbnail size most triangles of a large mesh cover no sample at all, so the cost is one pass
//! over the triangles, and the shading (perspective-correct vertex normals and vertex colours,
//! two-sided, per sample) costs the same for any mesh. 2x2 samples per pixel, box-filtered,
//! smooth the silhouette and the voxel steps the way the view's MSAA does.
//!
//! Triangles with a vertex that is not finite, behind the eye or out of range are skipped, as
//! are triangles without area on screen; parts beyond the camera's near and far planes are cut
//! per sample.

use super::{OrbitCamera, ViewUniforms};
use crate::srgb;
use glam::{Mat4, Vec3, Vec4, Vec4Swizzles};

/// The 3D view's background (`BACKGROUND` in the app's viewer), sRGB and opaque.
pub const BACKGROUND_SRGBA: [u8; 4] = [22, 24, 28, 255];

/// Samples per pixel along each axis.
const SUPERSAMPLING: usize = 2;

// The lights of shaders/render.wgsl (a test checks that they agree).
const AMBIENT: f32 = 0.07;
const KEY: f32 = 0.72;
const FILL: f32 = 0.3;
const SPECULAR: f32 = 0.22;
const SHININESS: f32 = 40.0;
const BACK_SHADE: f32 = 0.8;

/// No triangle at this sample.
const NONE: u32 = u32::MAX;

/// A rendered image: rows top to bottom, sRGB, straight (not premultiplied) alpha, the layout
/// `egui::ColorImage::from_rgba_unmultiplied` reads.
#[derive(Clone, Debug, PartialEq)]
pub struct Thumbnail {
    /// Width and height in pixels.
    pub size: [u32; 2],
    pub pixels: Vec<[u8; 4]>,
}

impl Thumbnail {
    /// The pixels as one byte slice, RGBA per pixel.
    pub fn as_bytes(&self) -> &[u8] {
        self.pixels.as_flattened()
    }
}

/// Renders the mesh as the 3D view would with `camera`, in an image of `size` pixels (the aspect
/// ratio follows from it), on the view's background. `colors` are sRGB per vertex; without them,
/// or when their count is not the vertex count, the view's base colour is used.
pub fn render(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    colors: Option<&[[u8; 4]]>,
    camera: &OrbitCamera,
    size: [u32; 2],
) -> Thumbnail {
    render_on(positions, triangles, colors, camera, size, BACKGROUND_SRGBA)
}

/// [`render`] on another background (sRGB, straight alpha); `[0; 4]` leaves it transparent.
pub fn render_on(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    colors: Option<&[[u8; 4]]>,
    camera: &OrbitCamera,
    size: [u32; 2],
    background: [u8; 4],
) -> Thumbnail {
    let [width, height] = size.map(|s| s as usize);
    let (sample_w, sample_h) = (width * SUPERSAMPLING, height * SUPERSAMPLING);
    let aspect = width as f32 / height as f32;
    let view = ViewUniforms::new(camera, aspect, 0);
    let screen = project(
        positions,
        Mat4::from_cols_array_2d(&view.view_proj),
        [sample_w, sample_h],
    );
    let visible = rasterize(&screen, triangles, [sample_w, sample_h]);
    let normals = visible_vertex_normals(positions, triangles, &visible);
    let albedo = colors.filter(|c| c.len() == positions.len()).map(|c| {
        let decode = srgb_decoding_table();
        c.iter()
            .map(|&[r, g, b, _]| {
                Vec3::new(decode[r as usize], decode[g as usize], decode[b as usize])
            })
            .collect::<Vec<_>>()
    });
    let shading = Shading {
        eye: Vec4::from(view.eye).xyz(),
        light: Vec4::from(view.light).xyz(),
        base_color: Vec4::from(view.base_color).xyz(),
        back_tint: Vec4::from(view.back_tint),
    };

    // Premultiplied linear background; samples are averaged premultiplied, as blending does.
    let bg_alpha = background[3] as f32 / 255.0;
    let bg = Vec3::from_array([0, 1, 2].map(|k| srgb::to_linear(background[k] as f32 / 255.0)))
        * bg_alpha;
    let samples = (SUPERSAMPLING * SUPERSAMPLING) as f32;
    let mut pixels = Vec::with_capacity(width * height);
    for y in 0..height {
        for x in 0..width {
            let (mut rgb, mut alpha) = (Vec3::ZERO, 0.0);
            for sy in y * SUPERSAMPLING..(y + 1) * SUPERSAMPLING {
                for sx in x * SUPERSAMPLING..(x + 1) * SUPERSAMPLING {
                    let t = visible[sy * sample_w + sx];
                    if t == NONE {
                        rgb += bg;
                        alpha += bg_alpha;
                        continue;
                    }
                    let corners = triangles[t as usize];
                    let at = [sx as f32 + 0.5, sy as f32 + 0.5];
                    rgb += shading.sample(
                        corners,
                        at,
                        &screen,
                        positions,
                        &normals,
                        albedo.as_deref(),
                    );
                    alpha += 1.0;
                }
            }
            pixels.push(encode(rgb / samples, alpha / samples));
        }
    }
    Thumbnail { size, pixels }
}

/// Each position in sample coordinates: x right and y down in samples, z the depth (0 near, 1
/// far), w the reciprocal of the clip-space w (for perspective-correct interpolation). All NaN
/// for positions that are not finite or not in front of the eye, else all finite.
fn project(positions: &[[f32; 3]], view_proj: Mat4, [w, h]: [usize; 2]) -> Vec<Vec4> {
    let (w, h) = (w as f32, h as f32);
    positions
        .iter()
        .map(|&p| {
            let clip = view_proj * Vec3::from(p).extend(1.0);
            if !(clip.is_finite() && clip.w > 0.0) {
                return Vec4::NAN;
            }
            let inv_w = 1.0 / clip.w;
            let s = Vec4::new(
                (clip.x * inv_w * 0.5 + 0.5) * w,
                (0.5 - clip.y * inv_w * 0.5) * h,
                clip.z * inv_w,
                inv_w,
            );
            if s.is_finite() {
                s
            } else {
                Vec4::NAN
            }
        })
        .collect()
}

/// The triangle's projected corners, if all its indices are in range and all are usable.
fn corners(screen: &[Vec4], [i, j, k]: [u32; 3]) -> Option<[Vec4; 3]> {
    let c = [
        *screen.get(i as usize)?,
        *screen.get(j as usize)?,
        *screen.get(k as usize)?,
    ];
    // Projected vertices are all finite or all NaN.
    c.iter().all(|v| !v.x.is_nan()).then_some(c)
}

/// Twice the signed area of the screen triangle (a, b, p): the edge function of a -> b at p.
fn edge(a: Vec4, b: Vec4, p: [f32; 2]) -> f32 {
    (b.x - a.x) * (p[1] - a.y) - (b.y - a.y) * (p[0] - a.x)
}

/// The samples whose centres (`i + 0.5`) lie in `min..=max`, clipped to `0..=last`; `None` when
/// there are none (or a bound is NaN). Truncating casts instead of `floor` and `ceil`, which are
/// library calls on x86-64 without SSE4.1: this runs once per triangle.
fn sample_span(min: f32, max: f32, last: usize) -> Option<(usize, usize)> {
    let (lo, hi) = (min - 0.5, max - 0.5);
    if !(hi >= 0.0 && lo <= last as f32) {
        return None;
    }
    // hi >= 0: truncation is floor.
    let end = (hi as usize).min(last);
    let start = if lo > 0.0 {
        // Ceiling of a positive value.
        let t = lo as usize;
        t + usize::from((t as f32) < lo)
    } else {
        0
    };
    (start <= end).then_some((start, end))
}

/// The nearest triangle at each sample (row-major), [`NONE`] where there is none.
fn rasterize(screen: &[Vec4], triangles: &[[u32; 3]], [w, h]: [usize; 2]) -> Vec<u32> {
    let mut depth = vec![f32::INFINITY; w * h];
    let mut visible = vec![NONE; w * h];
    let (max_x, max_y) = (w.saturating_sub(1), h.saturating_sub(1));
    if w == 0 || h == 0 {
        return visible;
    }
    // Indices at NONE and above cannot be stored; no mesh that fits in memory gets there.
    for (t, &tri) in triangles.iter().enumerate().take(NONE as usize) {
        let Some([a, b, c]) = corners(screen, tri) else {
            continue;
        };
        // The samples (centres at +0.5) inside the triangle's bounding box, clipped to the image.
        let Some((x0, x1)) = sample_span(a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x), max_x)
        else {
            continue;
        };
        let Some((y0, y1)) = sample_span(a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y), max_y)
        else {
            continue;
        };
        let area = edge(a, b, [c.x, c.y]);
        if !(area != 0.0 && area.is_finite()) {
            continue;
        }
        let inv_area = 1.0 / area;
        for y in y0..=y1 {
            let row = y * w;
            for x in x0..=x1 {
                let p = [x as f32 + 0.5, y as f32 + 0.5];
                // Barycentric weights; dividing by the signed area makes both windings positive
                // inside. Edges are inclusive: a sample on a shared edge is drawn by both
                // triangles and the depth test picks one, so closed meshes have no cracks.
                let wa = edge(b, c, p) * inv_area;
                let wb = edge(c, a, p) * inv_area;
                let wc = 1.0 - wa - wb;
                if wa < 0.0 || wb < 0.0 || wc < 0.0 {
                    continue;
                }
                let z = wa * a.z + wb * b.z + wc * c.z;
                let i = row + x;
                if (0.0..=1.0).contains(&z) && z < depth[i] {
                    depth[i] = z;
                    visible[i] = t as u32;
                }
            }
        }
    }
    visible
}

/// Area-weighted vertex normals (not normalised), only for the vertices of visible triangles:
/// the others are never shaded, and skipping them saves most of the pass on a large mesh.
/// Triangles with a non-finite corner or an index out of range add nothing.
fn visible_vertex_normals(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    visible: &[u32],
) -> Vec<Vec3> {
    let mut needed = vec![false; positions.len()];
    for &t in visible {
        if t != NONE {
            for v in triangles[t as usize] {
                needed[v as usize] = true;
            }
        }
    }
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for tri in triangles {
        let [i, j, k] = tri.map(|v| v as usize);
        let wanted = |v: usize| needed.get(v).copied().unwrap_or(false);
        if !(wanted(i) || wanted(j) || wanted(k))
            || j >= positions.len()
            || k >= positions.len()
            || i >= positions.len()
        {
            continue;
        }
        let [a, b, c] = [i, j, k].map(|v| Vec3::from(positions[v]));
        let n = (b - a).cross(c - a);
        if !n.is_finite() {
            continue;
        }
        for v in [i, j, k] {
            normals[v] += n;
        }
    }
    normals
}

/// The lights and colours of `fs_surface` in shaders/render.wgsl, linear RGB.
struct Shading {
    eye: Vec3,
    /// Unit vector towards the key light.
    light: Vec3,
    base_color: Vec3,
    /// Back-face tint, alpha = how much of it.
    back_tint: Vec4,
}

impl Shading {
    /// The lit colour (linear RGB) of the triangle `corners` at the sample point `at`.
    fn sample(
        &self,
        corners: [u32; 3],
        at: [f32; 2],
        screen: &[Vec4],
        positions: &[[f32; 3]],
        normals: &[Vec3],
        albedo: Option<&[Vec3]>,
    ) -> Vec3 {
        // The rasteriser only keeps triangles whose corners are valid.
        let [i, j, k] = corners.map(|v| v as usize);
        let [a, b, c] = [screen[i], screen[j], screen[k]];
        let area = edge(a, b, [c.x, c.y]);
        // Screen-space weights, clamped (inclusive edges) and made perspective-correct.
        let wa = (edge(b, c, at) / area).max(0.0) * a.w;
        let wb = (edge(c, a, at) / area).max(0.0) * b.w;
        let wc = (edge(a, b, at) / area).max(0.0) * c.w;
        let sum = wa + wb + wc;
        let weights = if sum > 0.0 && sum.is_finite() {
            [wa, wb, wc].map(|w| w / sum)
        } else {
            [1.0 / 3.0; 3]
        };
        let mix = |v: [Vec3; 3]| weights[0] * v[0] + weights[1] * v[1] + weights[2] * v[2];

        let world = mix([i, j, k].map(|v| Vec3::from(positions[v])));
        let to_eye = (self.eye - world).normalize_or(Vec3::Z);
        // Vertices without area have a zero normal: lit as if facing the eye.
        let mut n = mix([normals[i], normals[j], normals[k]])
            .try_normalize()
            .unwrap_or(to_eye);
        let mut color = albedo.map_or(self.base_color, |albedo| {
            mix([albedo[i], albedo[j], albedo[k]])
        });
        // Counter-clockwise on screen is front-facing (wgpu's default); with y down here that is
        // a negative area.
        if area > 0.0 {
            n = -n;
            color = color.lerp(self.back_tint.xyz(), self.back_tint.w) * BACK_SHADE;
        }
        let key = n.dot(self.light).max(0.0);
        let fill = n.dot(to_eye).max(0.0);
        let highlight = if key > 0.0 {
            n.dot((self.light + to_eye).normalize_or_zero())
                .max(0.0)
                // An integer power: multiplications, not a library call.
                .powi(SHININESS as i32)
        } else {
            0.0
        };
        color * (AMBIENT + KEY * key + FILL * fill) + Vec3::splat(SPECULAR * highlight)
    }
}

/// Linear light of each sRGB byte value.
fn srgb_decoding_table() -> [f32; 256] {
    std::array::from_fn(|v| srgb::to_linear(v as f32 / 255.0))
}

/// A pixel from premultiplied linear RGB and coverage: sRGB bytes, straight alpha.
fn encode(rgb: Vec3, alpha: f32) -> [u8; 4] {
    let byte = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    if alpha <= 0.0 {
        return [0; 4];
    }
    let straight = rgb / alpha;
    [
        byte(srgb::from_linear(straight.x)),
        byte(srgb::from_linear(straight.y)),
        byte(srgb::from_linear(straight.z)),
        byte(alpha),
    ]
}

#[cfg(test)]
mod tests;
