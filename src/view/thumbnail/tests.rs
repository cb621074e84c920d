use super::*;
use crate::view::{first_view, DEFAULT_FOV, RENDER_SHADER};

const SIZE: [u32; 2] = [64, 48];

/// Looking from +Y at the origin from 10 units away: the screen's right is -X, up is +Z.
fn camera() -> OrbitCamera {
    OrbitCamera {
        target: Vec3::ZERO,
        distance: 10.0,
        yaw: 0.0,
        pitch: 0.0,
        fov: DEFAULT_FOV,
        bounds_center: Vec3::ZERO,
        bounds_radius: 3.0,
    }
}

fn pixel(image: &Thumbnail, x: u32, y: u32) -> [u8; 4] {
    image.pixels[(y * image.size[0] + x) as usize]
}

/// A triangle in the plane y = `y` facing the eye (counter-clockwise seen from +Y).
fn facing(y: f32, scale: f32) -> Vec<[f32; 3]> {
    vec![[scale, y, -scale], [-scale, y, -scale], [0.0, y, scale]]
}

#[test]
fn a_triangle_covers_the_pixels_it_projects_to() {
    let positions = vec![[1.0, 0.0, -1.5], [-2.0, 0.0, -1.0], [0.5, 0.0, 2.0]];
    let image = render(&positions, &[[0, 1, 2]], None, &camera(), SIZE);
    assert_eq!(image.size, SIZE);
    assert_eq!(image.pixels.len(), (SIZE[0] * SIZE[1]) as usize);

    // Where the corners land, in pixels (y down), by the view's own matrix.
    let view_proj = camera().view_proj(SIZE[0] as f32 / SIZE[1] as f32);
    let screen: Vec<Vec4> = project(&positions, view_proj, SIZE.map(|s| s as usize));
    let [a, b, c] = [screen[0], screen[1], screen[2]];
    let area = edge(a, b, [c.x, c.y]);
    let length = |p: Vec4, q: Vec4| (q.xy() - p.xy()).length();
    let (mut inside, mut outside) = (0, 0);
    for y in 0..SIZE[1] {
        for x in 0..SIZE[0] {
            let centre = [x as f32 + 0.5, y as f32 + 0.5];
            // Distance of the pixel's centre inside each edge (negative: outside).
            let d = [
                edge(b, c, centre) / area * area.abs() / length(b, c),
                edge(c, a, centre) / area * area.abs() / length(c, a),
                edge(a, b, centre) / area * area.abs() / length(a, b),
            ];
            let p = pixel(&image, x, y);
            // Half a pixel's diagonal: the whole pixel is on one side.
            if d.iter().all(|&d| d > 0.71) {
                inside += 1;
                assert_eq!(p[3], 255);
                // Lit ivory, not the background, and not blended with it.
                assert!(p[0] > 120 && p[0] > p[2], "pixel ({x}, {y}) = {p:?}");
            } else if d.iter().any(|&d| d < -0.71) {
                outside += 1;
                assert_eq!(p, BACKGROUND_SRGBA, "pixel ({x}, {y})");
            }
        }
    }
    assert!(
        inside > 100 && outside > 1000,
        "{inside} inside, {outside} outside"
    );
    // The triangle reaches to the world's -X, the screen's right, of the centre.
    assert_ne!(pixel(&image, 40, 24), BACKGROUND_SRGBA);
    assert_eq!(pixel(&image, 8, 24), BACKGROUND_SRGBA);
}

#[test]
fn the_nearer_triangle_wins_in_either_order() {
    let mut positions = facing(2.0, 1.0);
    positions.extend(facing(-2.0, 2.0));
    let red = [255, 0, 0, 255];
    let blue = [0, 0, 255, 255];
    let colors = [red, red, red, blue, blue, blue];
    for triangles in [[[0, 1, 2], [3, 4, 5]], [[3, 4, 5], [0, 1, 2]]] {
        let image = render(&positions, &triangles, Some(&colors), &camera(), SIZE);
        let centre = pixel(&image, SIZE[0] / 2, SIZE[1] / 2);
        // Red lit, plus the white specular highlight.
        assert!(centre[0] > 200 && centre[2] < 100, "{centre:?}");
        // The farther, larger triangle shows around the nearer one.
        let below = pixel(&image, SIZE[0] / 2, SIZE[1] / 2 + 11);
        assert!(below[2] > 200 && below[0] < 100, "{below:?}");
    }
}

#[test]
fn back_faces_are_lit_and_tinted() {
    let positions = facing(0.0, 2.0);
    let front = pixel(
        &render(&positions, &[[0, 1, 2]], None, &camera(), SIZE),
        32,
        24,
    );
    let back = pixel(
        &render(&positions, &[[0, 2, 1]], None, &camera(), SIZE),
        32,
        24,
    );
    let sum = |p: [u8; 4]| p[0] as u32 + p[1] as u32 + p[2] as u32;
    assert!(sum(back) > 150, "the inside is lit too: {back:?}");
    assert!(sum(back) < sum(front), "{back:?} vs {front:?}");
    // Redder: green falls more than red.
    assert!((back[1] as f32 / back[0] as f32) < (front[1] as f32 / front[0] as f32));
}

#[test]
fn an_empty_mesh_gives_the_background() {
    let image = render(&[], &[], None, &camera(), SIZE);
    assert!(image.pixels.iter().all(|&p| p == BACKGROUND_SRGBA));
    let clear = render_on(&[], &[], None, &camera(), SIZE, [0; 4]);
    assert!(clear.pixels.iter().all(|&p| p == [0; 4]));
    assert!(render(&[], &[], None, &camera(), [0, 0]).pixels.is_empty());
    assert_eq!(render(&[], &[], None, &camera(), [0, 5]).pixels.len(), 0);
}

#[test]
fn unusable_triangles_are_skipped() {
    let nan = f32::NAN;
    let mut positions = facing(0.0, 2.0);
    positions.extend([
        [nan, 0.0, 0.0],
        [f32::INFINITY, 0.0, 1.0],
        // Behind the eye, and at the eye.
        [0.0, 20.0, 0.0],
        [0.0, 10.0, 0.0],
        [0.0, 1e30, 0.0],
    ]);
    let triangles = [
        [3, 1, 2],
        [4, 0, 1],
        [0, 5, 1],
        [6, 2, 0],
        [7, 0, 1],
        [0, 1, 99],
        // Repeated corners: no area.
        [0, 0, 1],
        [1, 1, 1],
    ];
    let colors = vec![[200, 10, 10, 255]; positions.len()];
    for colors in [None, Some(&colors[..]), Some(&colors[..2])] {
        let image = render(&positions, &triangles, colors, &camera(), SIZE);
        assert!(image.pixels.iter().all(|&p| p == BACKGROUND_SRGBA));
    }
    // A usable triangle among them covers what it covers alone (its shading may differ:
    // triangles behind the eye still bend its vertex normals).
    let mut with_one = triangles.to_vec();
    with_one.push([0, 1, 2]);
    let covered = |image: Thumbnail| -> Vec<bool> {
        image
            .pixels
            .iter()
            .map(|&p| p != BACKGROUND_SRGBA)
            .collect()
    };
    let among = covered(render(&positions, &with_one, None, &camera(), SIZE));
    let alone = covered(render(&positions, &[[0, 1, 2]], None, &camera(), SIZE));
    assert!(among == alone && alone.iter().filter(|&&c| c).count() > 100);
}

#[test]
fn a_real_mesh_fills_the_middle_of_the_image() {
    // Embedded: the library's tests also run in a browser.
    let bytes = include_bytes!("../../../../shared/data/real/fsaverage5_pial_left.ply");
    let mesh = crate::io::load(bytes, "fsaverage5_pial_left.ply").expect("a valid PLY");
    let size = [160, 120];
    let image = render(
        &mesh.positions,
        &mesh.triangles,
        None,
        &first_view(&mesh.positions),
        size,
    );
    let covered: Vec<[f32; 2]> = (0..size[1])
        .flat_map(|y| (0..size[0]).map(move |x| (x, y)))
        .filter(|&(x, y)| pixel(&image, x, y) != BACKGROUND_SRGBA)
        .map(|(x, y)| [x as f32 + 0.5, y as f32 + 0.5])
        .collect();
    let fraction = covered.len() as f32 / (size[0] * size[1]) as f32;
    assert!(fraction > 0.25, "covers {fraction}");
    let (lo, hi) = covered
        .iter()
        .fold(([f32::MAX; 2], [f32::MIN; 2]), |(lo, hi), p| {
            (
                [lo[0].min(p[0]), lo[1].min(p[1])],
                [hi[0].max(p[0]), hi[1].max(p[1])],
            )
        });
    // Fitted: the extent's middle at the image's, and it nearly spans the shorter side.
    for k in 0..2 {
        let middle = (lo[k] + hi[k]) * 0.5;
        let centre = size[k] as f32 * 0.5;
        assert!((middle - centre).abs() < 3.0, "axis {k}: {lo:?}..{hi:?}");
    }
    assert!(hi[1] - lo[1] > 0.8 * size[1] as f32, "{lo:?}..{hi:?}");
    // Shaded, not flat: a range of brightness.
    let lightness = |p: [u8; 4]| p[0] as u32 + p[1] as u32 + p[2] as u32;
    let lit: Vec<u32> = image
        .pixels
        .iter()
        .filter(|&&p| p != BACKGROUND_SRGBA)
        .map(|&p| lightness(p))
        .collect();
    let (min, max) = (lit.iter().min().unwrap(), lit.iter().max().unwrap());
    assert!(max - min > 200, "lightness {min}..{max}");
}

#[test]
fn the_lights_are_those_of_the_render_shader() {
    for (name, value) in [
        ("AMBIENT", AMBIENT),
        ("KEY", KEY),
        ("FILL", FILL),
        ("SPECULAR", SPECULAR),
        ("SHININESS", SHININESS),
        ("BACK_SHADE", BACK_SHADE),
    ] {
        let line = format!("const {name}: f32 = {value:?};");
        assert!(RENDER_SHADER.contains(&line), "render.wgsl lacks `{line}`");
    }
}

#[test]
fn srgb_encoding_inverts_decoding() {
    for v in 0..=255u8 {
        let linear = crate::srgb::to_linear(v as f32 / 255.0);
        assert_eq!(encode(Vec3::splat(linear), 1.0)[0], v);
    }
    assert_eq!(encode(Vec3::ZERO, 0.0), [0; 4]);
}

/// Speed on the large staircase mesh (206,512 vertices, 414,236 triangles):
/// `cargo test --release --lib view::thumbnail -- --ignored --nocapture`. Reported, not
/// asserted: machines are shared and noisy.
#[test]
#[ignore]
#[cfg(not(target_arch = "wasm32"))]
fn speed_on_the_large_mesh() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/data/segmentations/seg_mni152_gm_plus_wm_p0.5_1mm.ply"
    );
    let bytes = std::fs::read(path).expect("the shared test meshes");
    let mesh = crate::io::load(&bytes, path).expect("a valid PLY");
    let camera = first_view(&mesh.positions);
    let colors: Vec<[u8; 4]> = (0..mesh.positions.len())
        .map(|v| [(v % 256) as u8, 128, 200, 255])
        .collect();
    for (name, colors) in [("base colour", None), ("vertex colours", Some(&colors[..]))] {
        for size in [[160, 120], [320, 240]] {
            let mut best = f64::INFINITY;
            for _ in 0..10 {
                let start = std::time::Instant::now();
                let image = render(&mesh.positions, &mesh.triangles, colors, &camera, size);
                best = best.min(start.elapsed().as_secs_f64());
                std::hint::black_box(image);
            }
            println!(
                "{} vertices, {} triangles, {}x{}, {name}: best of 10 {:.1} ms",
                mesh.positions.len(),
                mesh.triangles.len(),
                size[0],
                size[1],
                best * 1e3
            );
        }
    }
}
