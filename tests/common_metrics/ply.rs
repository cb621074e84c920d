//! A small reader for binary little-endian PLY, enough for the shared test meshes (and any
//! file with float/double x y z vertices and list faces). Triangulates polygons as fans.
#![allow(dead_code)]

use meshsmooth::mesh::Mesh;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Result<Self, String> {
        Ok(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return Err(format!("unknown PLY type {name:?}")),
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    /// Reads one value at `*at` (advancing it) as f64.
    fn read(self, bytes: &[u8], at: &mut usize) -> Result<f64, String> {
        let n = self.size();
        let b = bytes
            .get(*at..*at + n)
            .ok_or_else(|| format!("PLY body ends early at byte {at}"))?;
        *at += n;
        Ok(match self {
            Scalar::I8 => b[0] as i8 as f64,
            Scalar::U8 => b[0] as f64,
            Scalar::I16 => i16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::U16 => u16::from_le_bytes([b[0], b[1]]) as f64,
            Scalar::I32 => i32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            Scalar::F64 => f64::from_le_bytes(b.try_into().map_err(|_| "short read")?),
        })
    }
}

#[derive(Debug)]
enum Property {
    Scalar(String, Scalar),
    List(String, Scalar, Scalar),
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

/// Parses a binary little-endian PLY file.
pub fn parse(bytes: &[u8]) -> Result<Mesh, String> {
    const END: &[u8] = b"end_header\n";
    let header_end = bytes
        .windows(END.len())
        .position(|w| w == END)
        .ok_or("no end_header")?
        + END.len();
    let header = std::str::from_utf8(&bytes[..header_end]).map_err(|e| e.to_string())?;
    let mut lines = header.lines();
    if lines.next() != Some("ply") {
        return Err("not a PLY file".into());
    }
    let mut elements: Vec<Element> = Vec::new();
    for line in lines {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["format", "binary_little_endian", _] => {}
            ["format", other, _] => return Err(format!("unsupported PLY format {other}")),
            ["element", name, count] => elements.push(Element {
                name: name.to_string(),
                count: count.parse().map_err(|_| format!("bad count {count:?}"))?,
                properties: Vec::new(),
            }),
            ["property", "list", count, item, name] => elements
                .last_mut()
                .ok_or("property before element")?
                .properties
                .push(Property::List(
                    name.to_string(),
                    Scalar::parse(count)?,
                    Scalar::parse(item)?,
                )),
            ["property", ty, name] => elements
                .last_mut()
                .ok_or("property before element")?
                .properties
                .push(Property::Scalar(name.to_string(), Scalar::parse(ty)?)),
            ["comment", ..] | ["obj_info", ..] | ["end_header"] | [] => {}
            _ => return Err(format!("unexpected header line {line:?}")),
        }
    }
    let mut at = header_end;
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for e in &elements {
        for _ in 0..e.count {
            let mut p = [0.0f32; 3];
            for prop in &e.properties {
                match prop {
                    Property::Scalar(name, ty) => {
                        let v = ty.read(bytes, &mut at)?;
                        if e.name == "vertex" {
                            match name.as_str() {
                                "x" => p[0] = v as f32,
                                "y" => p[1] = v as f32,
                                "z" => p[2] = v as f32,
                                _ => {}
                            }
                        }
                    }
                    Property::List(name, count_ty, item_ty) => {
                        let count = count_ty.read(bytes, &mut at)? as usize;
                        let mut poly = Vec::with_capacity(count);
                        for _ in 0..count {
                            poly.push(item_ty.read(bytes, &mut at)?);
                        }
                        let is_face = e.name == "face"
                            && (name == "vertex_indices" || name == "vertex_index");
                        if is_face {
                            for k in 1..count.saturating_sub(1) {
                                triangles.push([poly[0], poly[k], poly[k + 1]].map(|v| v as u32));
                            }
                        }
                    }
                }
            }
            if e.name == "vertex" {
                positions.push(p);
            }
        }
    }
    if let Some(bad) = triangles
        .iter()
        .flatten()
        .find(|&&v| v as usize >= positions.len())
    {
        return Err(format!("face index {bad} out of range"));
    }
    Ok(Mesh::new(positions, triangles))
}
