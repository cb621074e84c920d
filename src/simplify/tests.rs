use super::*;
use crate::metrics::point_triangle_distance2;

/// A sphere of `radius` mm: an icosahedron subdivided `levels` times, pushed onto the sphere.
fn sphere(radius: f32, levels: usize) -> Mesh {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut positions: Vec<[f32; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut middle = std::collections::HashMap::new();
        let mut next = Vec::new();
        for t in &triangles {
            let mut m = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
                m[k] = *middle.entry((a, b)).or_insert_with(|| {
                    let (p, q) = (positions[a as usize], positions[b as usize]);
                    positions.push(std::array::from_fn(|i| 0.5 * (p[i] + q[i])));
                    positions.len() as u32 - 1
                });
            }
            next.extend([
                [t[0], m[0], m[2]],
                [t[1], m[1], m[0]],
                [t[2], m[2], m[1]],
                m,
            ]);
        }
        triangles = next;
    }
    for p in &mut positions {
        let l = p.iter().map(|v| v * v).sum::<f32>().sqrt();
        *p = p.map(|v| v * radius / l);
    }
    Mesh::new(positions, triangles)
}

/// The deviation by brute force: every point against every triangle.
fn brute_force(surface: &Mesh, triangles: &[[u32; 3]]) -> f64 {
    let p = |v: u32| surface.positions[v as usize].map(f64::from);
    let nearest = |q: [f64; 3], set: &[[u32; 3]]| {
        set.iter()
            .map(|t| point_triangle_distance2(q, p(t[0]), p(t[1]), p(t[2])))
            .fold(f64::INFINITY, f64::min)
            .sqrt()
    };
    let away = (0..surface.positions.len() as u32)
        .map(|v| nearest(p(v), triangles))
        .fold(0.0, f64::max);
    let back = triangles
        .iter()
        .flat_map(|t| {
            let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
            let mix = |w: [f64; 3]| -> [f64; 3] {
                std::array::from_fn(|k| w[0] * a[k] + w[1] * b[k] + w[2] * c[k])
            };
            [
                mix([1.0 / 3.0; 3]),
                mix([0.5, 0.5, 0.0]),
                mix([0.0, 0.5, 0.5]),
                mix([0.5, 0.0, 0.5]),
            ]
        })
        .map(|q| nearest(q, &surface.triangles))
        .fold(0.0, f64::max);
    away.max(back)
}

#[test]
fn a_sphere_simplified_within_a_distance_stays_within_it_and_closed() {
    let s = sphere(20.0, 4);
    for mm in [0.1, 0.5] {
        let out = simplify(&s, Goal::Within(mm)).expect("simplifies");
        assert!(
            out.triangles.len() < s.triangle_count(),
            "{mm}: {}",
            out.triangles.len()
        );
        if mm >= 0.5 {
            assert!(
                out.triangles.len() < s.triangle_count() / 3,
                "{mm}: {}",
                out.triangles.len()
            );
        }
        assert!(
            out.deviation_mm <= mm && out.deviation_mm > 0.0,
            "{mm}: {}",
            out.deviation_mm
        );
        let measured = brute_force(&s, &out.triangles);
        assert!(
            (measured - out.deviation_mm).abs() <= 0.01 * measured,
            "{mm}: stated {} measured {measured}",
            out.deviation_mm
        );
        assert_eq!(shape(&s, &out.triangles), shape(&s, &s.triangles));
        assert_eq!(
            folds(
                &s,
                &out.triangles,
                &vertex_normals(&s.positions, &s.triangles)
            ),
            0
        );
    }
}

#[test]
fn a_triangle_count_is_met_and_its_deviation_stated() {
    let s = sphere(20.0, 4);
    let out = simplify(&s, Goal::Triangles(500)).expect("simplifies");
    assert!(out.triangles.len() <= 600, "{}", out.triangles.len());
    let measured = brute_force(&s, &out.triangles);
    assert!((measured - out.deviation_mm).abs() <= 0.01 * measured);
    assert_eq!(shape(&s, &out.triangles), shape(&s, &s.triangles));
}

#[test]
fn an_open_surface_or_a_goal_of_nothing_is_left_as_it_is() {
    let mut open = sphere(5.0, 2);
    open.triangles.pop();
    assert_eq!(simplify(&open, Goal::Within(0.1)), None);
    let s = sphere(5.0, 2);
    assert_eq!(simplify(&s, Goal::Within(0.0)), None);
    assert_eq!(simplify(&s, Goal::Within(f64::NAN)), None);
    assert_eq!(simplify(&s, Goal::Triangles(s.triangle_count())), None);
}
