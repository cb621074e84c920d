//! A small binary little-endian PLY reader for the shared test meshes, so engine tests can load
//! them on their own. It reads the header's elements and properties, takes `x y z` from the
//! vertex element and `vertex_indices` (or `vertex_index`) from the face element, and
//! fan-triangulates polygons.

#![allow(dead_code)]

use meshsmooth::mesh::Mesh;

/// Loads a PLY file from `../shared/data/<relative>`.
pub fn load_shared(relative: &str) -> Mesh {
    let path = format!("{}/../shared/data/{relative}", env!("CARGO_MANIFEST_DIR"));
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    parse(&bytes).unwrap_or_else(|e| panic!("{path}: {e}"))
}

struct Property {
    name: String,
    /// `Some(count type)` for a list property.
    list_count: Option<String>,
    kind: String,
}

struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

fn size_of(kind: &str) -> Result<usize, String> {
    Ok(match kind {
        "char" | "uchar" | "int8" | "uint8" => 1,
        "short" | "ushort" | "int16" | "uint16" => 2,
        "int" | "uint" | "float" | "int32" | "uint32" | "float32" => 4,
        "double" | "float64" => 8,
        _ => return Err(format!("unknown property type {kind}")),
    })
}

fn read(bytes: &[u8], at: &mut usize, kind: &str) -> Result<f64, String> {
    let n = size_of(kind)?;
    let b = bytes
        .get(*at..*at + n)
        .ok_or_else(|| format!("file ends at byte {at}"))?;
    *at += n;
    let v = match kind {
        "char" | "int8" => b[0] as i8 as f64,
        "uchar" | "uint8" => b[0] as f64,
        "short" | "int16" => i16::from_le_bytes([b[0], b[1]]) as f64,
        "ushort" | "uint16" => u16::from_le_bytes([b[0], b[1]]) as f64,
        "int" | "int32" => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        "uint" | "uint32" => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        "float" | "float32" => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        _ => f64::from_le_bytes(b.try_into().map_err(|_| "short double")?),
    };
    Ok(v)
}

pub fn parse(bytes: &[u8]) -> Result<Mesh, String> {
    const END: &[u8] = b"end_header\n";
    let end = bytes
        .windows(END.len())
        .position(|w| w == END)
        .ok_or("no end_header")?
        + END.len();
    let header = std::str::from_utf8(&bytes[..end]).map_err(|e| e.to_string())?;
    let mut elements: Vec<Element> = Vec::new();
    for line in header.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["format", f, _] if *f != "binary_little_endian" => {
                return Err(format!("format {f} not supported"))
            }
            ["element", name, count] => elements.push(Element {
                name: name.to_string(),
                count: count.parse().map_err(|_| format!("bad count in {line}"))?,
                properties: Vec::new(),
            }),
            ["property", "list", count, kind, name] => elements
                .last_mut()
                .ok_or("property before element")?
                .properties
                .push(Property {
                    name: name.to_string(),
                    list_count: Some(count.to_string()),
                    kind: kind.to_string(),
                }),
            ["property", kind, name] => elements
                .last_mut()
                .ok_or("property before element")?
                .properties
                .push(Property {
                    name: name.to_string(),
                    list_count: None,
                    kind: kind.to_string(),
                }),
            _ => {}
        }
    }
    let mut at = end;
    let mut mesh = Mesh::default();
    for e in &elements {
        for _ in 0..e.count {
            let mut xyz = [0.0f32; 3];
            for p in &e.properties {
                if let Some(count_kind) = &p.list_count {
                    let count = read(bytes, &mut at, count_kind)? as usize;
                    let mut ids = Vec::with_capacity(count);
                    for _ in 0..count {
                        ids.push(read(bytes, &mut at, &p.kind)? as u32);
                    }
                    if e.name == "face" && p.name.starts_with("vertex_ind") {
                        for k in 1..count.saturating_sub(1) {
                            mesh.triangles.push([ids[0], ids[k], ids[k + 1]]);
                        }
                    }
                } else {
                    let v = read(bytes, &mut at, &p.kind)?;
                    if e.name == "vertex" {
                        match p.name.as_str() {
                            "x" => xyz[0] = v as f32,
                            "y" => xyz[1] = v as f32,
                            "z" => xyz[2] = v as f32,
                            _ => {}
                        }
                    }
                }
            }
            if e.name == "vertex" {
                mesh.positions.push(xyz);
            }
        }
    }
    let n = mesh.positions.len() as u32;
    if mesh.triangles.iter().flatten().any(|&v| v >= n) {
        return Err("face index out of range".into());
    }
    Ok(mesh)
}
