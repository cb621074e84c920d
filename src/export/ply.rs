//! Binary little-endian PLY: float xyz (then nx ny nz, then uchar red green blue alpha when
//! given) and `uchar int` triangle lists.

use super::{ExportError, ExportOptions};
use crate::mesh::Mesh;

pub(super) fn write(mesh: &Mesh, options: &ExportOptions) -> Result<Vec<u8>, ExportError> {
    // Faces store indices as PLY `int`.
    if i32::try_from(mesh.vertex_count()).is_err() {
        return Err(ExportError::TooLarge {
            format: "PLY",
            detail: format!("{} vertices do not fit int indices", mesh.vertex_count()),
        });
    }
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment meshsmooth\nelement vertex {}\n\
         property float x\nproperty float y\nproperty float z\n",
        mesh.vertex_count()
    );
    if options.normals.is_some() {
        header.push_str("property float nx\nproperty float ny\nproperty float nz\n");
    }
    if options.colors.is_some() {
        header.push_str(
            "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n",
        );
    }
    header.push_str(&format!(
        "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.triangle_count()
    ));

    let vertex_size = 12 + options.normals.map_or(0, |_| 12) + options.colors.map_or(0, |_| 4);
    let mut out = Vec::with_capacity(
        header.len() + mesh.vertex_count() * vertex_size + mesh.triangle_count() * 13,
    );
    out.extend_from_slice(header.as_bytes());
    for (i, p) in mesh.positions.iter().enumerate() {
        p.iter().for_each(|v| out.extend(v.to_le_bytes()));
        // Lengths were checked against the vertex count by the caller.
        if let Some(n) = options.normals.and_then(|n| n.get(i)) {
            n.iter().for_each(|v| out.extend(v.to_le_bytes()));
        }
        if let Some(c) = options.colors.and_then(|c| c.get(i)) {
            out.extend_from_slice(c);
        }
    }
    for t in &mesh.triangles {
        out.push(3);
        // Below i32::MAX, checked above.
        t.iter().for_each(|&v| out.extend((v as i32).to_le_bytes()));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_and_records_are_laid_out_as_declared() {
        let mesh = Mesh::new(
            vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]],
            vec![[0, 1, 2]],
        );
        let colors = [[10, 20, 30, 40]; 3];
        let options = ExportOptions {
            colors: Some(&colors),
            ..Default::default()
        };
        let bytes = write(&mesh, &options).expect("writes");
        let end = b"end_header\n";
        let body = bytes
            .windows(end.len())
            .position(|w| w == end)
            .map(|i| i + end.len())
            .expect("header ends");
        let header = std::str::from_utf8(&bytes[..body]).expect("ASCII header");
        assert!(header.contains("comment meshsmooth\n"));
        assert!(header.contains("element vertex 3\n"));
        assert!(!header.contains("nx"));
        assert!(header.contains("property uchar alpha\n"));
        // 3 vertices of 16 bytes, one face of 13.
        assert_eq!(bytes.len() - body, 3 * 16 + 13);
        assert_eq!(&bytes[body..body + 4], &1.0f32.to_le_bytes());
        assert_eq!(&bytes[body + 12..body + 16], &[10, 20, 30, 40]);
        let face = &bytes[body + 48..];
        assert_eq!(face[0], 3);
        assert_eq!(&face[9..13], &2i32.to_le_bytes());
    }
}
