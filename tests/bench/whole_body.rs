//! A synthetic whole-body CT segmentation of the size TotalSegmentator writes: 512 x 512 x 400
//! voxels of 0.8 x 0.8 x 1.0 mm, 114 structures (organs and lung lobes, 24 vertebrae, 24 ribs,
//! 20 vessels from 1.5 to 12 mm radius, muscles, bones of the limbs and pelvis, and lesions
//! inside organs), written as a gzipped NIfTI-1 label map with a colour table beside it.
//!
//!     cargo run --release --example whole_body -- OUT_DIR [--scale S]
//!
//! writes OUT_DIR/whole_body.nii.gz and OUT_DIR/whole_body_labels.txt. `--scale` shrinks the
//! grid (0.5: 256 x 256 x 200 voxels of twice the size) for quick tries; the anatomy stays the
//! same in millimetres. The shapes are made here, deterministic, with no patient data.

use std::io::Write;

#[path = "whole_body_anatomy.rs"]
mod anatomy;
#[path = "../common/nifti.rs"]
mod nifti;

use anatomy::{Shape, P};

/// Grid size and spacing at scale 1.
const DIMS: [usize; 3] = [512, 512, 400];
const SPACING: [f64; 3] = [0.8, 0.8, 1.0];

/// Voxel grid at a scale: dims and spacing.
struct Grid {
    dims: [usize; 3],
    spacing: [f64; 3],
}

impl Grid {
    fn index_range(&self, lo: P, hi: P, axis: usize) -> std::ops::Range<usize> {
        let a = (lo[axis] / self.spacing[axis] - 0.5).floor().max(0.0) as usize;
        let b = ((hi[axis] / self.spacing[axis] - 0.5).ceil() + 1.0).max(0.0) as usize;
        a.min(self.dims[axis])..b.min(self.dims[axis])
    }

    /// Calls `inside` at the centre of every voxel of the box [lo, hi] and labels the voxel
    /// where it says so.
    fn fill(&self, labels: &mut [u8], label: u8, lo: P, hi: P, inside: impl Fn(P) -> bool) {
        let [nx, ny, _] = self.dims;
        for k in self.index_range(lo, hi, 2) {
            for j in self.index_range(lo, hi, 1) {
                for i in self.index_range(lo, hi, 0) {
                    let p = [
                        (i as f64 + 0.5) * self.spacing[0],
                        (j as f64 + 0.5) * self.spacing[1],
                        (k as f64 + 0.5) * self.spacing[2],
                    ];
                    if inside(p) {
                        labels[i + nx * (j + ny * k)] = label;
                    }
                }
            }
        }
    }

    fn draw(&self, labels: &mut [u8], label: u8, shape: &Shape) {
        match shape {
            Shape::Blob {
                centre,
                radii,
                yaw,
                bump,
                keep,
            } => {
                let r = radii.iter().fold(0.0f64, |m, &v| m.max(v)) * (1.0 + bump);
                let lo = [centre[0] - r, centre[1] - r, centre[2] - r];
                let hi = [centre[0] + r, centre[1] + r, centre[2] + r];
                let (c, s) = (yaw.cos(), yaw.sin());
                self.fill(labels, label, lo, hi, |p| {
                    if let Some((n, d)) = keep {
                        if n[0] * p[0] + n[1] * p[1] + n[2] * p[2] < *d {
                            return false;
                        }
                    }
                    let d = [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]];
                    let l = [
                        (c * d[0] + s * d[1]) / radii[0],
                        (-s * d[0] + c * d[1]) / radii[1],
                        d[2] / radii[2],
                    ];
                    let q = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
                    let wobble = (3.0 * l[0]).sin() * (2.0 * l[1]).cos() + (2.5 * l[2]).sin() * 0.5;
                    q < 1.0 + bump * wobble
                });
            }
            Shape::Tube { path, radius } => {
                for w in path.windows(2) {
                    let (a, b) = (w[0], w[1]);
                    let lo = [0, 1, 2].map(|k| a[k].min(b[k]) - radius);
                    let hi = [0, 1, 2].map(|k| a[k].max(b[k]) + radius);
                    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
                    let len2 = (ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2]).max(1e-12);
                    self.fill(labels, label, lo, hi, |p| {
                        let ap = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
                        let t = ((ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2]) / len2)
                            .clamp(0.0, 1.0);
                        let d = [ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]];
                        d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < radius * radius
                    });
                }
            }
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(out) = args.first() else {
        return Err("usage: whole_body OUT_DIR [--scale S]".into());
    };
    let scale: f64 = match args.iter().position(|a| a == "--scale") {
        Some(i) => args.get(i + 1).ok_or("--scale needs a value")?.parse()?,
        None => 1.0,
    };
    if !(0.05..=1.0).contains(&scale) {
        return Err("--scale is a fraction in (0, 1]".into());
    }
    let grid = Grid {
        dims: DIMS.map(|d| ((d as f64 * scale).round() as usize).max(1)),
        spacing: SPACING.map(|s| s / scale),
    };
    let structures = anatomy::all();
    assert!(structures.len() < 255, "labels are one byte");
    let [nx, ny, nz] = grid.dims;
    let mut labels = vec![0u8; nx * ny * nz];
    for (i, s) in structures.iter().enumerate() {
        for shape in &s.shapes {
            grid.draw(&mut labels, (i + 1) as u8, shape);
        }
    }
    std::fs::create_dir_all(out)?;
    let path = std::path::Path::new(out);
    let file = std::fs::File::create(path.join("whole_body.nii.gz"))?;
    let mut gz =
        flate2::write::GzEncoder::new(std::io::BufWriter::new(file), flate2::Compression::fast());
    let [sx, sy, sz] = grid.spacing.map(|s| s as f32);
    let sform = [
        [sx, 0.0, 0.0, 0.0],
        [0.0, sy, 0.0, 0.0],
        [0.0, 0.0, sz, 0.0],
    ];
    gz.write_all(&nifti::nifti_header(grid.dims, sform, [sx, sy, sz]))?;
    gz.write_all(&labels)?;
    gz.finish()?.flush()?;
    let mut table = String::from("# index name R G B A\n0 background 0 0 0 0\n");
    for (i, s) in structures.iter().enumerate() {
        let [r, g, b] = s.color;
        table += &format!("{} {} {r} {g} {b} 255\n", i + 1, s.name);
    }
    std::fs::write(path.join("whole_body_labels.txt"), table)?;
    let counts = labels.iter().fold([0usize; 256], |mut c, &l| {
        c[l as usize] += 1;
        c
    });
    let empty: Vec<&str> = (structures.iter().enumerate())
        .filter(|(i, _)| counts[i + 1] == 0)
        .map(|(_, s)| s.name.as_str())
        .collect();
    println!(
        "{} structures on {nx} x {ny} x {nz} voxels of {:.2} x {:.2} x {:.2} mm{}",
        structures.len(),
        grid.spacing[0],
        grid.spacing[1],
        grid.spacing[2],
        if empty.is_empty() {
            String::new()
        } else {
            format!("; empty: {}", empty.join(", "))
        }
    );
    Ok(())
}
