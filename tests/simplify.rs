//! Simplification within a distance or to a triangle count, on spheres: the stated deviation
//! is the one measured, the surface stays closed, manifold and of its genus, no triangle turns
//! against the surface, and what cannot be simplified is left alone.

use meshsmooth::mesh::{Mesh, MeshReport, Topology};
use meshsmooth::simplify::{simplify, Goal};

#[path = "common_metrics/shapes.rs"]
mod shapes;

#[path = "common/surface_deviation.rs"]
mod surface_deviation;

use surface_deviation::{facing_against, measured};

fn sound_like(before: &Mesh, triangles: &[[u32; 3]]) {
    let after = Mesh::new(before.positions.clone(), triangles.to_vec());
    let (r, was) = (
        MeshReport::new(&after, &Topology::build(&after)),
        MeshReport::new(before, &Topology::build(before)),
    );
    assert!(r.closed && r.boundary_edges == 0);
    assert_eq!(
        (
            r.nonmanifold_edges,
            r.nonmanifold_vertices,
            r.degenerate_faces
        ),
        (0, 0, 0)
    );
    assert_eq!((r.components, r.genus), (was.components, was.genus));
    assert_eq!(facing_against(before, &after), 0);
}

#[test]
fn a_sphere_simplified_within_a_distance_stays_within_it_closed_and_outward() {
    let s = shapes::icosphere(4, 20.0, [0.0; 3]);
    for mm in [0.2, 0.5] {
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
        let again = measured(&s, &Mesh::new(s.positions.clone(), out.triangles.clone()));
        assert!(
            (again - out.deviation_mm).abs() <= 0.01 * again,
            "{mm}: stated {} measured {again}",
            out.deviation_mm
        );
        sound_like(&s, &out.triangles);
    }
}

#[test]
fn a_triangle_count_is_met_and_its_deviation_stated() {
    let s = shapes::icosphere(4, 20.0, [0.0; 3]);
    let out = simplify(&s, Goal::Triangles(500)).expect("simplifies");
    assert!(out.triangles.len() <= 600, "{}", out.triangles.len());
    let again = measured(&s, &Mesh::new(s.positions.clone(), out.triangles.clone()));
    assert!((again - out.deviation_mm).abs() <= 0.01 * again);
    sound_like(&s, &out.triangles);
}

#[test]
fn an_open_surface_or_a_goal_of_nothing_is_left_as_it_is() {
    let mut open = shapes::icosphere(2, 5.0, [0.0; 3]);
    open.triangles.pop();
    assert_eq!(simplify(&open, Goal::Within(0.1)), None);
    let s = shapes::icosphere(2, 5.0, [0.0; 3]);
    assert_eq!(simplify(&s, Goal::Within(0.0)), None);
    assert_eq!(simplify(&s, Goal::Within(f64::NAN)), None);
    assert_eq!(simplify(&s, Goal::Triangles(s.triangle_count())), None);
}
