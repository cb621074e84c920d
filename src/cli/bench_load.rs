//! `meshsmooth bench-load FILE [--repeat N] [--json]`: how long reading a mesh takes, split into
//! parsing (bytes to indexed mesh, welding included) and building the topology; then what the
//! page's opening costs: the whole model built in a worker, and its trip to the page (encoded
//! there, decoded on the page's thread, which draws no frame meanwhile).
//!
//! The file is read into memory once so disk speed does not count; the best of `repeat` runs is
//! reported, the usual way to take noise from other processes out of a wall-clock timing.

use crate::case::Case;
use crate::io;
use crate::mesh::Topology;
use crate::model::Model;
use crate::worker;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// Best timings over the runs, in seconds.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LoadTiming {
    pub file: String,
    pub vertices: usize,
    pub faces: usize,
    pub parse_seconds: f64,
    pub topology_seconds: f64,
    /// Best single run of parse + topology (not the sum of the two bests).
    pub total_seconds: f64,
    /// The whole opening a worker does: parse, topology, checks, the original's measures.
    pub open_seconds: f64,
    /// The opened model in the workers' wire format.
    pub wire_bytes: usize,
    pub encode_seconds: f64,
    pub decode_seconds: f64,
}

pub fn run(path: &Path, repeat: usize, json: bool) -> Result<(), String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let timing = measure(&bytes, &path.display().to_string(), repeat)?;
    if json {
        let text = serde_json::to_string(&timing).map_err(|e| e.to_string())?;
        outln!("{text}");
    } else {
        outln!("{}", timing.file);
        outln!("  {} vertices, {} faces", timing.vertices, timing.faces);
        outln!(
            "  parse {:.2} ms, topology {:.2} ms, total {:.2} ms (best of {})",
            timing.parse_seconds * 1e3,
            timing.topology_seconds * 1e3,
            timing.total_seconds * 1e3,
            repeat.max(1)
        );
        outln!(
            "  opened as the page's workers do {:.2} ms; to the page: {:.1} MB, encode {:.2} ms, \
             decode {:.2} ms",
            timing.open_seconds * 1e3,
            timing.wire_bytes as f64 / 1e6,
            timing.encode_seconds * 1e3,
            timing.decode_seconds * 1e3
        );
    }
    Ok(())
}

/// Parses `bytes` (format from `name`'s extension) and builds its topology `repeat` times.
pub fn measure(bytes: &[u8], name: &str, repeat: usize) -> Result<LoadTiming, String> {
    let mut timing = LoadTiming {
        file: name.to_string(),
        vertices: 0,
        faces: 0,
        parse_seconds: f64::INFINITY,
        topology_seconds: f64::INFINITY,
        total_seconds: f64::INFINITY,
        open_seconds: f64::INFINITY,
        wire_bytes: 0,
        encode_seconds: f64::INFINITY,
        decode_seconds: f64::INFINITY,
    };
    for _ in 0..repeat.max(1) {
        let start = Instant::now();
        let mesh = io::load(bytes, name).map_err(|e| e.to_string())?;
        let parsed = Instant::now();
        let topology = Topology::build(&mesh);
        let built = Instant::now();
        // Keep the work observable so it cannot be optimised away; dropping is not timed.
        std::hint::black_box(&topology);
        let parse = (parsed - start).as_secs_f64();
        let topo = (built - parsed).as_secs_f64();
        timing.parse_seconds = timing.parse_seconds.min(parse);
        timing.topology_seconds = timing.topology_seconds.min(topo);
        timing.total_seconds = timing.total_seconds.min(parse + topo);
        timing.vertices = mesh.vertex_count();
        timing.faces = mesh.triangle_count();

        let start = Instant::now();
        let model = Model::load(name, bytes).map_err(|e| e.to_string())?;
        let opened = Instant::now();
        let wire = worker::encode(&(&model.model, &model.case));
        let encoded = Instant::now();
        let back: (Model, Case) = worker::decode(&wire)?;
        let decoded = Instant::now();
        std::hint::black_box(&back);
        timing.open_seconds = timing.open_seconds.min((opened - start).as_secs_f64());
        timing.encode_seconds = timing.encode_seconds.min((encoded - opened).as_secs_f64());
        timing.decode_seconds = timing.decode_seconds.min((decoded - encoded).as_secs_f64());
        timing.wire_bytes = wire.len();
    }
    Ok(timing)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn measures_a_small_stl_and_reports_load_errors() {
        let stl = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
            vertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
        let t = measure(stl, "t.stl", 3).expect("valid STL");
        assert_eq!((t.vertices, t.faces), (3, 1));
        assert!(t.parse_seconds.is_finite() && t.topology_seconds.is_finite());
        assert!(t.total_seconds >= t.parse_seconds && t.total_seconds >= t.topology_seconds);
        let json = serde_json::to_value(&t).expect("serialisable");
        for key in [
            "file",
            "vertices",
            "faces",
            "parse_seconds",
            "topology_seconds",
            "total_seconds",
            "open_seconds",
            "wire_bytes",
            "encode_seconds",
            "decode_seconds",
        ] {
            assert!(json.get(key).is_some(), "{key}");
        }
        assert!(measure(b"solid t\n", "t.stl", 1).is_err());
        assert!(run(Path::new("no/such/file.stl"), 1, false).is_err());
    }
}
