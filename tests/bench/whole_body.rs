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

use std::f64::consts::PI;
use std::io::Write;

/// Grid size and spacing at scale 1.
const DIMS: [usize; 3] = [512, 512, 400];
const SPACING: [f64; 3] = [0.8, 0.8, 1.0];

/// A point in millimetres: x to the patient's left, y posterior, z superior.
type P = [f64; 3];

/// One primitive of a structure's shape.
enum Shape {
    /// An ellipsoid rotated by `yaw` about z, its radius modulated by a low bump so that no two
    /// organs are the same smooth quadric; `keep` clips it to one side of a plane (lung lobes).
    Blob {
        centre: P,
        radii: P,
        yaw: f64,
        bump: f64,
        keep: Option<(P, f64)>,
    },
    /// A tube of `radius` along a polyline (vessels, ribs, bowel, cord).
    Tube { path: Vec<P>, radius: f64 },
}

struct Structure {
    name: String,
    color: [u8; 3],
    shapes: Vec<Shape>,
}

fn blob(centre: P, radii: P, yaw: f64) -> Shape {
    Shape::Blob {
        centre,
        radii,
        yaw,
        bump: 0.08,
        keep: None,
    }
}

fn tube(path: Vec<P>, radius: f64) -> Shape {
    Shape::Tube { path, radius }
}

fn one(name: &str, color: [u8; 3], shape: Shape) -> Structure {
    Structure {
        name: name.into(),
        color,
        shapes: vec![shape],
    }
}

/// Points along a curve given by `f` on [0, 1].
fn curve(n: usize, f: impl Fn(f64) -> P) -> Vec<P> {
    (0..=n).map(|i| f(i as f64 / n as f64)).collect()
}

const CX: f64 = 205.0;
const CY: f64 = 205.0;

fn organs() -> Vec<Structure> {
    let lung = |side: f64, upper: bool, middle: bool| {
        let centre = [CX + side * 75.0, CY + 5.0, 300.0];
        let (normal, offset) = ([0.0, 0.35 * side.signum(), 1.0], 300.0 - 10.0);
        let d = normal[1] * centre[1] + normal[2] * offset;
        let keep = if upper {
            (normal, d)
        } else {
            ([-normal[0], -normal[1], -normal[2]], -d)
        };
        let mut radii = [55.0, 75.0, 85.0];
        if middle {
            radii = [50.0, 60.0, 70.0];
        }
        Shape::Blob {
            centre,
            radii,
            yaw: 0.0,
            bump: 0.05,
            keep: Some(keep),
        }
    };
    let mut s = vec![
        one(
            "liver",
            [221, 130, 101],
            blob([CX - 60.0, CY - 10.0, 200.0], [95.0, 75.0, 70.0], 0.2),
        ),
        one(
            "spleen",
            [157, 108, 162],
            blob([CX + 95.0, CY + 40.0, 205.0], [30.0, 55.0, 50.0], -0.5),
        ),
        one(
            "kidney_left",
            [185, 102, 83],
            blob([CX + 60.0, CY + 60.0, 160.0], [28.0, 25.0, 55.0], 0.4),
        ),
        one(
            "kidney_right",
            [185, 102, 83],
            blob([CX - 60.0, CY + 60.0, 150.0], [28.0, 25.0, 55.0], -0.4),
        ),
        one(
            "gallbladder",
            [139, 150, 98],
            blob([CX - 45.0, CY - 55.0, 170.0], [15.0, 25.0, 35.0], 0.6),
        ),
        one(
            "stomach",
            [216, 132, 105],
            blob([CX + 55.0, CY - 30.0, 215.0], [50.0, 40.0, 55.0], 0.7),
        ),
        one(
            "pancreas",
            [249, 180, 111],
            blob([CX + 10.0, CY + 20.0, 175.0], [70.0, 14.0, 16.0], -0.25),
        ),
        one(
            "adrenal_gland_left",
            [249, 186, 150],
            blob([CX + 45.0, CY + 55.0, 205.0], [9.0, 14.0, 22.0], 0.3),
        ),
        one(
            "adrenal_gland_right",
            [249, 186, 150],
            blob([CX - 45.0, CY + 55.0, 200.0], [9.0, 14.0, 22.0], -0.3),
        ),
        one(
            "lung_upper_lobe_left",
            [197, 165, 145],
            lung(1.0, true, false),
        ),
        one(
            "lung_lower_lobe_left",
            [197, 165, 145],
            lung(1.0, false, false),
        ),
        one(
            "lung_upper_lobe_right",
            [197, 165, 145],
            lung(-1.0, true, false),
        ),
        one(
            "lung_lower_lobe_right",
            [197, 165, 145],
            lung(-1.0, false, false),
        ),
        one(
            "heart",
            [206, 110, 84],
            blob([CX + 15.0, CY - 35.0, 275.0], [55.0, 45.0, 50.0], 0.5),
        ),
        one(
            "thyroid_gland",
            [220, 160, 30],
            blob([CX, CY - 45.0, 385.0], [25.0, 10.0, 14.0], 0.0),
        ),
        one(
            "urinary_bladder",
            [222, 154, 132],
            blob([CX, CY - 50.0, 35.0], [40.0, 32.0, 30.0], 0.0),
        ),
        one(
            "prostate",
            [230, 158, 140],
            blob([CX, CY - 30.0, 12.0], [18.0, 14.0, 12.0], 0.0),
        ),
        one(
            "sternum",
            [244, 214, 49],
            blob([CX, CY - 105.0, 290.0], [16.0, 6.0, 80.0], 0.0),
        ),
    ];
    // The middle lobe: a smaller blob clipped below the right upper lobe's fissure.
    s.push(one("lung_middle_lobe_right", [197, 165, 145], {
        let mut b = lung(-1.0, false, true);
        if let Shape::Blob { centre, .. } = &mut b {
            *centre = [CX - 80.0, CY - 40.0, 270.0];
        }
        b
    }));
    let tubes = [
        (
            "esophagus",
            [211, 171, 143],
            curve(20, |t| {
                [CX + 8.0 * t, CY + 40.0 - 50.0 * t, 395.0 - 170.0 * t]
            }),
            8.0,
        ),
        (
            "trachea",
            [182, 228, 255],
            curve(10, |t| [CX, CY - 35.0, 398.0 - 90.0 * t]),
            9.0,
        ),
        (
            "spinal_cord",
            [244, 214, 49],
            curve(30, |t| {
                [CX, CY + 85.0 - 10.0 * (PI * t).sin(), 398.0 - 300.0 * t]
            }),
            5.0,
        ),
        (
            "duodenum",
            [255, 253, 229],
            curve(30, |t| {
                [
                    CX - 30.0 + 50.0 * (PI * t).cos(),
                    CY + 5.0 + 30.0 * (PI * t).sin(),
                    170.0 - 30.0 * t,
                ]
            }),
            11.0,
        ),
        (
            "small_bowel",
            [205, 167, 142],
            curve(400, |t| {
                let a = 14.0 * PI * t;
                [
                    CX + 20.0 + (50.0 - 20.0 * t) * a.cos(),
                    CY - 45.0 + 25.0 * a.sin(),
                    130.0 - 60.0 * t + 8.0 * (3.0 * a).sin(),
                ]
            }),
            9.0,
        ),
        (
            "colon",
            [204, 168, 143],
            {
                let mut p = curve(20, |t| [CX - 95.0, CY - 10.0, 60.0 + 80.0 * t]);
                p.extend(curve(30, |t| {
                    [
                        CX - 95.0 + 190.0 * t,
                        CY - 40.0 + 20.0 * (PI * t).sin(),
                        140.0 + 10.0 * (PI * t).sin(),
                    ]
                }));
                p.extend(curve(20, |t| [CX + 95.0, CY - 10.0, 140.0 - 90.0 * t]));
                p.extend(curve(20, |t| {
                    [CX + 95.0 - 80.0 * t, CY + 10.0 + 40.0 * t, 50.0 - 20.0 * t]
                }));
                p
            },
            17.0,
        ),
    ];
    for (name, color, path, radius) in tubes {
        s.push(one(name, color, tube(path, radius)));
    }
    s
}

fn bones_and_muscles() -> Vec<Structure> {
    let mut s = Vec::new();
    for (side, word) in [(1.0, "left"), (-1.0, "right")] {
        let x = |d: f64| CX + side * d;
        s.push(one(
            &format!("hip_{word}"),
            [212, 188, 102],
            Shape::Blob {
                centre: [x(85.0), CY + 20.0, 45.0],
                radii: [22.0, 60.0, 50.0],
                yaw: side * 0.5,
                bump: 0.15,
                keep: None,
            },
        ));
        s.push(one(
            &format!("femur_{word}"),
            [250, 250, 225],
            tube(
                curve(20, |t| [x(95.0 - 10.0 * t), CY - 10.0, 15.0 - 14.0 * t]),
                20.0,
            ),
        ));
        s.push(one(
            &format!("humerus_{word}"),
            [250, 250, 225],
            tube(
                curve(20, |t| [x(175.0), CY + 10.0, 370.0 - 200.0 * t]),
                13.0,
            ),
        ));
        s.push(one(
            &format!("scapula_{word}"),
            [200, 190, 140],
            Shape::Blob {
                centre: [x(105.0), CY + 105.0, 330.0],
                radii: [55.0, 8.0, 60.0],
                yaw: side * 0.45,
                bump: 0.2,
                keep: None,
            },
        ));
        s.push(one(
            &format!("clavicula_{word}"),
            [230, 220, 170],
            tube(
                curve(20, |t| {
                    [
                        x(15.0 + 140.0 * t),
                        CY - 90.0 + 70.0 * t * t,
                        372.0 + 8.0 * (PI * t).sin(),
                    ]
                }),
                7.0,
            ),
        ));
        s.push(one(
            &format!("gluteus_maximus_{word}"),
            [188, 95, 76],
            blob([x(80.0), CY + 95.0, 25.0], [55.0, 30.0, 55.0], side * 0.3),
        ));
        s.push(one(
            &format!("iliopsoas_{word}"),
            [176, 84, 70],
            tube(
                curve(20, |t| {
                    [x(30.0 + 50.0 * t), CY + 55.0 - 60.0 * t, 170.0 - 150.0 * t]
                }),
                16.0,
            ),
        ));
        s.push(one(
            &format!("autochthon_{word}"),
            [165, 80, 66],
            tube(
                curve(20, |t| {
                    [
                        x(35.0),
                        CY + 110.0 - 12.0 * (PI * t).sin(),
                        380.0 - 330.0 * t,
                    ]
                }),
                17.0,
            ),
        ));
    }
    s.push(one(
        "sacrum",
        [212, 188, 102],
        blob([CX, CY + 85.0, 30.0], [45.0, 22.0, 30.0], 0.0),
    ));
    s
}

fn spine() -> Vec<Structure> {
    let names = (1..=7)
        .map(|i| format!("vertebrae_C{i}"))
        .chain((1..=12).map(|i| format!("vertebrae_T{i}")))
        .chain((1..=5).map(|i| format!("vertebrae_L{i}")));
    let mut s = Vec::new();
    let mut z = 398.0;
    for (k, name) in names.enumerate() {
        // Bodies grow from the neck down; a disc's gap between them.
        let height = 7.5 + 8.0 * k as f64 / 23.0;
        let radius = 10.0 + 14.0 * k as f64 / 23.0;
        let y = CY + 60.0 - 10.0 * (PI * (398.0 - z) / 300.0).sin();
        let top = z;
        let bottom = z - height;
        let mid = 0.5 * (top + bottom);
        let body = tube(
            vec![
                [CX, y, top - radius.min(height) * 0.3],
                [CX, y, bottom + radius.min(height) * 0.3],
            ],
            radius,
        );
        let arch = tube(
            curve(16, |t| {
                let a = PI * (0.15 + 0.7 * t);
                [
                    CX + (radius + 8.0) * a.cos(),
                    y + radius + 4.0 + (radius * 0.6) * a.sin(),
                    mid,
                ]
            }),
            3.5,
        );
        let spinous = tube(
            vec![
                [CX, y + radius + 12.0, mid],
                [CX, y + radius + 32.0, mid - 10.0],
            ],
            4.0,
        );
        s.push(Structure {
            name,
            color: [241, 214, 145],
            shapes: vec![body, arch, spinous],
        });
        z = bottom - 2.5;
    }
    s
}

fn ribs() -> Vec<Structure> {
    let mut s = Vec::new();
    for (side, word) in [(1.0, "left"), (-1.0, "right")] {
        for i in 1..=12 {
            let z0 = 360.0 - 13.5 * (i - 1) as f64;
            let reach = if i > 10 { 0.55 } else { 0.92 };
            let width = 60.0 + 70.0 * ((i as f64 - 1.0) / 6.0).min(1.0);
            let path = curve(60, |t| {
                let a = PI * reach * t;
                [
                    CX + side * (15.0 + width * a.sin()),
                    CY + 70.0 - 0.5 * width * (1.0 - a.cos()) - 40.0 * t,
                    z0 - 35.0 * t,
                ]
            });
            s.push(one(
                &format!("rib_{word}_{i}"),
                [253, 232, 158],
                tube(path, 4.5),
            ));
        }
    }
    s
}

fn vessels() -> Vec<Structure> {
    let v = |name: &str, artery: bool, radius: f64, path: Vec<P>| {
        let color = if artery {
            [216, 101, 79]
        } else {
            [0, 151, 206]
        };
        one(name, color, tube(path, radius))
    };
    let line = |a: P, b: P| {
        curve(12, move |t| {
            [
                a[0] + (b[0] - a[0]) * t,
                a[1] + (b[1] - a[1]) * t,
                a[2] + (b[2] - a[2]) * t,
            ]
        })
    };
    let mut s = vec![
        v("aorta", true, 12.0, {
            let mut p = curve(20, |t| {
                [
                    CX + 10.0 - 10.0 * t,
                    CY - 20.0 + 30.0 * t,
                    260.0 + 60.0 * (PI * t).sin(),
                ]
            });
            p.extend(line([CX, CY + 10.0, 260.0], [CX + 10.0, CY + 35.0, 90.0]));
            p
        }),
        v(
            "inferior_vena_cava",
            false,
            11.0,
            line([CX - 25.0, CY + 30.0, 260.0], [CX - 20.0, CY + 30.0, 90.0]),
        ),
        v(
            "superior_vena_cava",
            false,
            9.0,
            line([CX - 25.0, CY - 30.0, 350.0], [CX - 20.0, CY - 25.0, 290.0]),
        ),
        v(
            "pulmonary_artery",
            true,
            12.0,
            curve(20, |t| {
                [
                    CX + 10.0 + 40.0 * t,
                    CY - 45.0 + 20.0 * t,
                    300.0 + 20.0 * (PI * t).sin(),
                ]
            }),
        ),
        v(
            "portal_vein",
            false,
            6.0,
            line([CX - 10.0, CY + 10.0, 180.0], [CX - 50.0, CY - 5.0, 205.0]),
        ),
        v(
            "splenic_vein",
            false,
            4.0,
            curve(20, |t| {
                [
                    CX - 10.0 + 100.0 * t,
                    CY + 12.0 + 15.0 * t,
                    180.0 + 15.0 * (PI * t).sin(),
                ]
            }),
        ),
        v(
            "brachiocephalic_trunk",
            true,
            6.0,
            line([CX - 5.0, CY - 25.0, 315.0], [CX - 20.0, CY - 35.0, 345.0]),
        ),
        v(
            "hepatic_artery",
            true,
            1.5,
            curve(30, |t| {
                [
                    CX - 5.0 - 45.0 * t,
                    CY + 15.0 - 10.0 * t,
                    185.0 + 12.0 * t + 4.0 * (3.0 * PI * t).sin(),
                ]
            }),
        ),
    ];
    for (side, word) in [(1.0, "left"), (-1.0, "right")] {
        let x = |d: f64| CX + side * d;
        s.push(v(
            &format!("common_carotid_artery_{word}"),
            true,
            3.5,
            line([x(8.0), CY - 25.0, 330.0], [x(25.0), CY - 25.0, 398.0]),
        ));
        s.push(v(
            &format!("subclavian_artery_{word}"),
            true,
            4.0,
            curve(20, |t| {
                [
                    x(12.0 + 120.0 * t),
                    CY - 15.0,
                    335.0 + 15.0 * (PI * t).sin(),
                ]
            }),
        ));
        s.push(v(
            &format!("iliac_artery_{word}"),
            true,
            5.0,
            line(
                [CX + side * 4.0, CY + 35.0, 92.0],
                [x(70.0), CY + 10.0, 20.0],
            ),
        ));
        s.push(v(
            &format!("iliac_vena_{word}"),
            false,
            6.0,
            line(
                [CX - 20.0 + side * 4.0, CY + 40.0, 92.0],
                [x(58.0), CY + 22.0, 18.0],
            ),
        ));
        let kidney = if side > 0.0 { 160.0 } else { 150.0 };
        s.push(v(
            &format!("renal_artery_{word}"),
            true,
            2.5,
            line(
                [CX + side * 10.0, CY + 30.0, kidney + 8.0],
                [x(45.0), CY + 55.0, kidney + 4.0],
            ),
        ));
        s.push(v(
            &format!("renal_vein_{word}"),
            false,
            3.5,
            line(
                [CX - 18.0 + side * 8.0, CY + 25.0, kidney - 4.0],
                [x(45.0), CY + 50.0, kidney - 6.0],
            ),
        ));
    }
    s
}

/// Lesions, each well inside its organ (drawn last, so they cut their place out of it).
fn lesions() -> Vec<Structure> {
    let round = |c: P, r: f64| Shape::Blob {
        centre: c,
        radii: [r, r * 0.9, r * 0.85],
        yaw: 0.3,
        bump: 0.1,
        keep: None,
    };
    vec![
        one(
            "liver_lesion_1",
            [253, 232, 158],
            round([CX - 80.0, CY - 20.0, 210.0], 14.0),
        ),
        one(
            "liver_lesion_2",
            [253, 232, 158],
            round([CX - 40.0, CY + 10.0, 185.0], 6.0),
        ),
        one(
            "kidney_lesion_left",
            [240, 200, 150],
            round([CX + 62.0, CY + 58.0, 175.0], 8.0),
        ),
        one(
            "lung_nodule_right",
            [250, 220, 170],
            round([CX - 80.0, CY + 10.0, 330.0], 5.0),
        ),
    ]
}

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

/// A NIfTI-1 header for `dims` uint8 labels, sform = scale by `spacing` (code 2, aligned).
fn nifti_header(dims: [usize; 3], spacing: [f64; 3]) -> Vec<u8> {
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    let dim: [i16; 8] = [
        3,
        dims[0] as i16,
        dims[1] as i16,
        dims[2] as i16,
        1,
        1,
        1,
        1,
    ];
    for (i, d) in dim.iter().enumerate() {
        h[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&2i16.to_le_bytes()); // uint8
    h[72..74].copy_from_slice(&8i16.to_le_bytes());
    let pixdim = [
        1.0f32,
        spacing[0] as f32,
        spacing[1] as f32,
        spacing[2] as f32,
    ];
    for (i, p) in pixdim.iter().enumerate() {
        h[76 + 4 * i..80 + 4 * i].copy_from_slice(&p.to_le_bytes());
    }
    h[108..112].copy_from_slice(&352f32.to_le_bytes());
    h[123] = 2; // xyzt_units: millimetres
    h[254..256].copy_from_slice(&2i16.to_le_bytes());
    for r in 0..3 {
        let mut row = [0f32; 4];
        row[r] = spacing[r] as f32;
        for (c, v) in row.iter().enumerate() {
            let at = 280 + 16 * r + 4 * c;
            h[at..at + 4].copy_from_slice(&v.to_le_bytes());
        }
    }
    h[344..348].copy_from_slice(b"n+1\0");
    h
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
    let mut structures = organs();
    structures.extend(bones_and_muscles());
    structures.extend(spine());
    structures.extend(ribs());
    structures.extend(vessels());
    structures.extend(lesions());
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
    gz.write_all(&nifti_header(grid.dims, grid.spacing))?;
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
