//! OBJ: `v` records with each f32 in its shortest round-trip decimal form (so a reader gets
//! the same bits back), `vn` when normals are given, 1-based `f` records.

use std::fmt::Write as _;

use super::ExportOptions;
use crate::mesh::Mesh;

pub(super) fn write(mesh: &Mesh, options: &ExportOptions) -> Vec<u8> {
    let mut out = String::with_capacity(32 * mesh.vertex_count() + 24 * mesh.triangle_count());
    out.push_str("# meshsmooth\n");
    // Writing to a String cannot fail.
    for p in &mesh.positions {
        let _ = writeln!(out, "v {} {} {}", p[0], p[1], p[2]);
    }
    if let Some(normals) = options.normals {
        for n in normals {
            let _ = writeln!(out, "vn {} {} {}", n[0], n[1], n[2]);
        }
    }
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|v| v as u64 + 1);
        let _ = if options.normals.is_some() {
            writeln!(out, "f {a}//{a} {b}//{b} {c}//{c}")
        } else {
            writeln!(out, "f {a} {b} {c}")
        };
    }
    out.into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shortest_forms_read_back_bit_exact() {
        let awkward = [0.1f32, -0.0, 1.0e-38, 3.4028235e38, 123.456_79, 1.0 / 3.0];
        let mesh = Mesh::new(
            vec![
                [awkward[0], awkward[1], awkward[2]],
                [awkward[3], awkward[4], awkward[5]],
                [0.0; 3],
            ],
            vec![[0, 1, 2]],
        );
        let normals = [[0.0, 0.0, 1.0]; 3];
        let options = ExportOptions {
            normals: Some(&normals),
            ..Default::default()
        };
        let text = String::from_utf8(write(&mesh, &options)).expect("UTF-8");
        let read: Vec<f32> = text
            .lines()
            .filter_map(|l| l.strip_prefix("v "))
            .flat_map(|l| l.split(' ').map(|v| v.parse::<f32>().expect("number")))
            .collect();
        let written: Vec<u32> = mesh
            .positions
            .iter()
            .flatten()
            .map(|v| v.to_bits())
            .collect();
        assert_eq!(
            read.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            written
        );
        assert!(text.contains("\nvn 0 0 1\n"));
        assert!(text.ends_with("f 1//1 2//2 3//3\n"));
    }
}
