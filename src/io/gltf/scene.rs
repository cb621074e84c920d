//! The node hierarchy: which meshes are drawn, where, in traversal order. Transforms are
//! accumulated in f64 so that deep hierarchies do not lose the precision the positions have.

use ::gltf::json::Root;

use super::super::{Format, LoadError, Location};

/// 4x4 matrix, column-major like glTF: `m[column][row]`.
pub type Mat4 = [[f64; 4]; 4];

pub(super) const IDENTITY: Mat4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// A mesh placed by a node, with the node's world transform.
#[derive(Clone, Debug)]
pub(super) struct Instance {
    pub node: usize,
    pub mesh: usize,
    pub matrix: Mat4,
    /// The node's own transform (its frame's part of `matrix`).
    pub local: Mat4,
}

fn syntax(format: Format, what: &'static str, index: usize, detail: String) -> LoadError {
    LoadError::Syntax {
        format,
        location: Location::Item(what, index),
        detail,
    }
}

/// The meshes of the default scene (else scene 0, else every root node), depth first with
/// children in the order listed. A node reached twice (a cycle, or two parents) is an error:
/// the specification requires the nodes to form disjoint trees.
pub(super) fn instances(root: &Root, format: Format) -> Result<Vec<Instance>, LoadError> {
    let roots: Vec<usize> = match (root.scene, root.scenes.first()) {
        (Some(s), _) => root
            .scenes
            .get(s.value())
            .ok_or_else(|| {
                syntax(
                    format,
                    "scene",
                    s.value(),
                    "the default scene does not exist".into(),
                )
            })?
            .nodes
            .iter()
            .map(|n| n.value())
            .collect(),
        (None, Some(scene)) => scene.nodes.iter().map(|n| n.value()).collect(),
        (None, None) => {
            let mut is_child = vec![false; root.nodes.len()];
            for node in &root.nodes {
                for c in node.children.iter().flatten() {
                    if let Some(flag) = is_child.get_mut(c.value()) {
                        *flag = true;
                    }
                }
            }
            (0..root.nodes.len()).filter(|&i| !is_child[i]).collect()
        }
    };

    let mut visited = vec![false; root.nodes.len()];
    let mut out = Vec::new();
    // Reversed so that popping visits the roots, and later each node's children, in order.
    let mut stack: Vec<(usize, Mat4)> = roots.iter().rev().map(|&n| (n, IDENTITY)).collect();
    while let Some((index, parent)) = stack.pop() {
        let node = root.nodes.get(index).ok_or_else(|| {
            syntax(
                format,
                "node",
                index,
                format!("does not exist ({} nodes)", root.nodes.len()),
            )
        })?;
        match visited.get_mut(index) {
            Some(seen) if !*seen => *seen = true,
            _ => {
                return Err(syntax(
                    format,
                    "node",
                    index,
                    "is reached twice: the node hierarchy is not a tree".into(),
                ))
            }
        }
        let local = local_matrix(node, index, format)?;
        let world = multiply(&parent, &local);
        if let Some(mesh) = node.mesh {
            out.push(Instance {
                node: index,
                mesh: mesh.value(),
                matrix: world,
                local,
            });
        }
        for child in node.children.iter().flatten().rev() {
            stack.push((child.value(), world));
        }
    }
    Ok(out)
}

/// A node's own transform: its `matrix`, or translation * rotation * scale.
fn local_matrix(
    node: &::gltf::json::Node,
    index: usize,
    format: Format,
) -> Result<Mat4, LoadError> {
    let m = if let Some(m) = node.matrix {
        let c = |k: usize| [m[4 * k], m[4 * k + 1], m[4 * k + 2], m[4 * k + 3]].map(f64::from);
        [c(0), c(1), c(2), c(3)]
    } else {
        let t = node.translation.unwrap_or([0.0; 3]).map(f64::from);
        let s = node.scale.unwrap_or([1.0; 3]).map(f64::from);
        let q = node
            .rotation
            .map_or([0.0, 0.0, 0.0, 1.0], |r| r.0.map(f64::from));
        let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            return Err(syntax(
                format,
                "node",
                index,
                format!("rotation {q:?} is not a unit quaternion"),
            ));
        }
        // Writers round unit quaternions to f32; renormalising keeps the rotation rigid.
        let [x, y, z, w] = q.map(|v| v / norm);
        let r = [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y + w * z),
                2.0 * (x * z - w * y),
            ],
            [
                2.0 * (x * y - w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z + w * x),
            ],
            [
                2.0 * (x * z + w * y),
                2.0 * (y * z - w * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ];
        let col = |k: usize| [r[k][0] * s[k], r[k][1] * s[k], r[k][2] * s[k], 0.0];
        [col(0), col(1), col(2), [t[0], t[1], t[2], 1.0]]
    };
    if let Some(v) = m.iter().flatten().find(|v| !v.is_finite()) {
        return Err(LoadError::NonFinite {
            format,
            location: Location::Item("node", index),
            value: format!("{v} in its transform"),
        });
    }
    Ok(m)
}

pub(super) fn multiply(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut out = [[0.0; 4]; 4];
    for (c, col) in out.iter_mut().enumerate() {
        for (r, v) in col.iter_mut().enumerate() {
            *v = (0..4).map(|k| a[k][r] * b[c][k]).sum();
        }
    }
    out
}

/// Transforms a point (w = 1), rounding once to f32 at the end.
pub(super) fn transform_point(m: &Mat4, p: [f32; 3]) -> [f32; 3] {
    let [x, y, z] = p.map(f64::from);
    let row = |r: usize| (m[0][r] * x + m[1][r] * y + m[2][r] * z + m[3][r]) as f32;
    [row(0), row(1), row(2)]
}

/// Determinant of the linear part; negative means the transform mirrors, which reverses winding.
pub(super) fn determinant3(m: &Mat4) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2])
        - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trs_quarter_turn_about_z() {
        let h = std::f32::consts::FRAC_1_SQRT_2;
        let node: ::gltf::json::Node = serde_json::from_value(serde_json::json!({
            "translation": [1.0, 2.0, 3.0],
            "rotation": [0.0, 0.0, h, h],
            "scale": [2.0, 2.0, 2.0]
        }))
        .expect("valid node");
        let m = local_matrix(&node, 0, Format::Gltf).expect("finite");
        let p = transform_point(&m, [1.0, 0.0, 0.0]);
        // Scale to (2,0,0), rotate to (0,2,0), translate to (1,4,3).
        for (got, want) in p.iter().zip([1.0, 4.0, 3.0]) {
            assert!((got - want).abs() < 1e-6, "{p:?}");
        }
        assert!((determinant3(&m) - 8.0).abs() < 1e-9);
    }

    #[test]
    fn multiply_applies_right_operand_first() {
        let mut t = IDENTITY;
        t[3] = [5.0, 0.0, 0.0, 1.0];
        let mut s = IDENTITY;
        s[0][0] = 3.0;
        let p = transform_point(&multiply(&t, &s), [1.0, 0.0, 0.0]);
        assert_eq!(p, [8.0, 0.0, 0.0]);
    }
}
