//! `meshsmooth info FILE [--json]`.

use crate::mesh::{MeshReport, Topology};
use std::path::Path;

pub(super) fn run(file: &Path, json: bool) -> Result<(), String> {
    let mesh = super::load_file(file)?;
    let report = MeshReport::new(&mesh, &Topology::build(&mesh));
    if json {
        println!("{}", super::to_json(&report)?);
    } else {
        print!("{}", text(&report));
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
