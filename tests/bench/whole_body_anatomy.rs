//! The anatomy of the synthetic whole-body CT (tests/bench/whole_body.rs): each structure as
//! primitives in millimetres, x to the patient's left, y posterior, z superior.

use std::f64::consts::PI;

/// A point in millimetres.
pub type P = [f64; 3];

/// One primitive of a structure's shape.
pub enum Shape {
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

pub struct Structure {
    pub name: String,
    pub color: [u8; 3],
    pub shapes: Vec<Shape>,
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

/// Organs as bumped ellipsoids: name, colour, centre (x and y from the body's axis), radii,
/// yaw.
#[rustfmt::skip]
const BLOBS: &[(&str, [u8; 3], P, P, f64)] = &[
    ("liver", [221, 130, 101], [-60.0, -10.0, 200.0], [95.0, 75.0, 70.0], 0.2),
    ("spleen", [157, 108, 162], [95.0, 40.0, 205.0], [30.0, 55.0, 50.0], -0.5),
    ("kidney_left", [185, 102, 83], [60.0, 60.0, 160.0], [28.0, 25.0, 55.0], 0.4),
    ("kidney_right", [185, 102, 83], [-60.0, 60.0, 150.0], [28.0, 25.0, 55.0], -0.4),
    ("gallbladder", [139, 150, 98], [-45.0, -55.0, 170.0], [15.0, 25.0, 35.0], 0.6),
    ("stomach", [216, 132, 105], [55.0, -30.0, 215.0], [50.0, 40.0, 55.0], 0.7),
    ("pancreas", [249, 180, 111], [10.0, 20.0, 175.0], [70.0, 14.0, 16.0], -0.25),
    ("adrenal_gland_left", [249, 186, 150], [45.0, 55.0, 205.0], [9.0, 14.0, 22.0], 0.3),
    ("adrenal_gland_right", [249, 186, 150], [-45.0, 55.0, 200.0], [9.0, 14.0, 22.0], -0.3),
    ("heart", [206, 110, 84], [15.0, -35.0, 275.0], [55.0, 45.0, 50.0], 0.5),
    ("thyroid_gland", [220, 160, 30], [0.0, -45.0, 385.0], [25.0, 10.0, 14.0], 0.0),
    ("urinary_bladder", [222, 154, 132], [0.0, -50.0, 35.0], [40.0, 32.0, 30.0], 0.0),
    ("prostate", [230, 158, 140], [0.0, -30.0, 12.0], [18.0, 14.0, 12.0], 0.0),
    ("sternum", [244, 214, 49], [0.0, -105.0, 290.0], [16.0, 6.0, 80.0], 0.0),
];

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
    let mut s: Vec<Structure> = (BLOBS.iter())
        .map(|&(name, color, [x, y, z], radii, yaw)| {
            one(name, color, blob([CX + x, CY + y, z], radii, yaw))
        })
        .collect();
    s.push(one(
        "lung_upper_lobe_left",
        [197, 165, 145],
        lung(1.0, true, false),
    ));
    s.push(one(
        "lung_lower_lobe_left",
        [197, 165, 145],
        lung(1.0, false, false),
    ));
    s.push(one(
        "lung_upper_lobe_right",
        [197, 165, 145],
        lung(-1.0, true, false),
    ));
    s.push(one(
        "lung_lower_lobe_right",
        [197, 165, 145],
        lung(-1.0, false, false),
    ));
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

/// Every structure, in label order (lesions last, so they cut their place out of their organ).
pub fn all() -> Vec<Structure> {
    let mut structures = organs();
    structures.extend(bones_and_muscles());
    structures.extend(spine());
    structures.extend(ribs());
    structures.extend(vessels());
    structures.extend(lesions());
    structures
}
