//! `meshsmooth info FILE [--json]`.

use crate::mesh::{MeshReport, Topology};
use std::path::Path;

pub(super) fn run(file: &Path, json: bool) -> Result<(), String> {
    if crate::io::is_label_map(&file.to_string_lossy()) {
        return label_map(file, json);
    }
    let mesh = super::load_file(file)?;
    let report = MeshReport::new(&mesh, &Topology::build(&mesh));
    if json {
        outln!("{}", super::to_json(&report)?);
    } else {
        out!("{}", text(&report));
    }
    Ok(())
}

fn text(r: &MeshReport) -> String {
    let mut s = String::new();
    let opt = |v: Option<String>| v.unwrap_or_else(|| "undefined".to_string());
    s += &format!("vertices               {}\n", r.vertices);
    s += &format!("faces                  {}\n", r.faces);
    s += &format!("unreferenced vertices  {}\n", r.unreferenced_vertices);
    s += &format!("degenerate faces       {}\n", r.degenerate_faces);
    s += &format!("duplicate faces        {}\n", r.duplicate_faces);
    s += &format!("boundary edges         {}\n", r.boundary_edges);
    s += &format!("non-manifold edges     {}\n", r.nonmanifold_edges);
    s += &format!("non-manifold vertices  {}\n", r.nonmanifold_vertices);
    s += &format!("components             {}\n", r.components);
    s += &format!("euler characteristic   {}\n", r.euler);
    s += &format!(
        "genus                  {}\n",
        opt(r.genus.map(|g| g.to_string()))
    );
    s += &format!("closed                 {}\n", r.closed);
    s += &format!(
        "volume                 {}\n",
        opt(r.volume.map(|v| format!("{v:.3}")))
    );
    s += &format!("bbox min               {:?}\n", r.bbox_min);
    s += &format!("bbox max               {:?}\n", r.bbox_max);
    for w in r.warnings() {
        s += &format!("warning: {w}\n");
    }
    s
}

/// A label map's grid and the structures it holds (their voxels; `extract` makes the surfaces).
fn label_map(file: &Path, json: bool) -> Result<(), String> {
    let bytes = std::fs::read(file).map_err(|e| format!("{}: {e}", file.display()))?;
    let map = crate::io::load_label_map(&bytes, &file.to_string_lossy(), &Default::default())
        .map_err(|e| format!("{}: {e}", file.display()))?;
    let labels = crate::segmentation::labels(&map, &[]);
    let spacing = map.spacing();
    let voxel_volume: f64 = spacing.iter().product();
    if json {
        let list: Vec<_> = labels
            .iter()
            .map(|l| {
                serde_json::json!({
                    "layer": l.layer, "label": l.label, "name": l.name, "color": l.color,
                    "voxels": l.voxels, "voxel_volume": l.voxels as f64 * voxel_volume,
                })
            })
            .collect();
        let out = serde_json::json!({
            "dims": map.dims,
            "voxel_size": spacing,
            "affine": map.affine.0,
            "layers": map.layers.len(),
            "structures": list,
        });
        outln!("{}", super::to_json(&out)?);
        return Ok(());
    }
    outln!(
        "grid                   {} x {} x {}",
        map.dims[0],
        map.dims[1],
        map.dims[2]
    );
    outln!(
        "voxel size             {:.4} x {:.4} x {:.4} mm",
        spacing[0],
        spacing[1],
        spacing[2]
    );
    outln!("layers                 {}", map.layers.len());
    outln!("structures             {}", labels.len());
    for l in &labels {
        outln!(
            "{:>6}  {:<40} {:>10} voxels {:>12.1} mm3",
            l.label,
            l.name,
            l.voxels,
            l.voxels as f64 * voxel_volume
        );
    }
    Ok(())
}
