//! Named, coloured structure surfaces from a label map: which labels, their names and colours,
//! and the surfaces themselves.

use super::extract::{surfaces_by_code, to_world};
use super::palette::default_color;
use super::specks::drop_small_components;
use crate::io::{Affine, LabelMap, Segment, StructureCodes};
use crate::mesh::Mesh;

/// Which labels to extract.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExtractOptions {
    /// Label values to extract; empty extracts every label present.
    pub labels: Vec<i64>,
    /// Voxel components (6-connected, as the surfaces separate them) smaller than this are
    /// dropped first; 0 or 1 keeps everything.
    pub min_voxels: usize,
}

/// One labelled structure: its surface in world millimetres (RAS) and what it is.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Structure {
    pub label: i64,
    /// The label map's layer (several only in a `.seg.nrrd` with overlapping segments).
    pub layer: usize,
    pub name: String,
    /// Display (sRGB) colour, each channel in [0, 1].
    pub color: [f32; 3],
    /// Voxels of the label (after dropping specks).
    pub voxels: usize,
    /// Voxel size along i, j, k in mm.
    pub voxel_size: [f64; 3],
    /// The voxel grid it was extracted on: its vertices lie at the world points of the grid's
    /// edge midpoints.
    pub grid: Affine,
    /// What it is in standard codes, where its name is one the shipped table knows.
    #[serde(default)]
    pub codes: Option<StructureCodes>,
    /// Closed, outward-wound, manifold.
    pub mesh: Mesh,
}

impl Structure {
    /// The voxel diagonal in mm: the unit of the error legend, and twice the default bound.
    pub fn voxel_diagonal(&self) -> f64 {
        self.voxel_size.iter().map(|s| s * s).sum::<f64>().sqrt()
    }

    /// The label's volume counted in voxels, in mm³.
    pub fn voxel_volume(&self) -> f64 {
        self.voxels as f64 * self.voxel_size.iter().product::<f64>()
    }
}

/// A label the label map holds, without its surface (what `info` lists).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct LabelInfo {
    pub layer: usize,
    pub label: i64,
    pub name: String,
    pub color: [f32; 3],
    pub voxels: usize,
}

/// Every label present, in the order [`extract`] makes their structures, named as it names
/// them.
pub fn labels(map: &LabelMap, names: &[Segment]) -> Vec<LabelInfo> {
    let mut out = Vec::new();
    for (index, layer) in map.layers.iter().enumerate() {
        let counts = code_counts(&layer.codes, layer.values.len());
        for (code, &voxels) in counts.iter().enumerate().skip(1) {
            if voxels == 0 {
                continue;
            }
            let label = layer.values[code];
            let (name, color, _) = naming(map, names, index, label, out.len());
            out.push(LabelInfo {
                layer: index,
                label,
                name,
                color,
                voxels,
            });
        }
    }
    out
}

/// Why no structures could be made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExtractError {
    #[error("label {value} is not in the label map (its labels: {present})")]
    NoSuchLabel { value: i64, present: String },
    #[error("the label map holds no labelled voxels")]
    Empty,
    #[error("every component is smaller than {min_voxels} voxels: nothing is left")]
    AllSpecks { min_voxels: usize },
}

/// Extracts one surface per label present (or per label asked for), named and coloured from
/// the label map's own segments first, then from `names` (a colour table), else `label N` with
/// the default palette. Structures come in label order, layer by layer.
pub fn extract(
    map: &LabelMap,
    names: &[Segment],
    options: &ExtractOptions,
) -> Result<Vec<Structure>, ExtractError> {
    check_labels(map, &options.labels)?;
    let voxel_size = map.spacing();
    let mut out = Vec::new();
    for (index, layer) in map.layers.iter().enumerate() {
        let cleaned;
        let layer = if options.min_voxels > 1 {
            let mut copy = layer.clone();
            drop_small_components(&mut copy, map.dims, options.min_voxels);
            cleaned = copy;
            &cleaned
        } else {
            layer
        };
        let counts = code_counts(&layer.codes, layer.values.len());
        let wanted: Vec<bool> = layer
            .values
            .iter()
            .zip(&counts)
            .enumerate()
            .map(|(code, (value, &n))| {
                code != 0 && n > 0 && (options.labels.is_empty() || options.labels.contains(value))
            })
            .collect();
        let surfaces = surfaces_by_code(map.dims, layer, &wanted);
        for (code, mesh) in surfaces.into_iter().enumerate() {
            let Some(mut mesh) = mesh else { continue };
            to_world(&mut mesh, map);
            let value = layer.values[code];
            let (name, color, codes) = naming(map, names, index, value, out.len());
            out.push(Structure {
                label: value,
                layer: index,
                codes,
                name,
                color,
                voxels: counts[code],
                voxel_size,
                grid: map.affine,
                mesh,
            });
        }
    }
    if out.is_empty() {
        return Err(if options.min_voxels > 1 {
            ExtractError::AllSpecks {
                min_voxels: options.min_voxels,
            }
        } else {
            ExtractError::Empty
        });
    }
    Ok(out)
}

/// Refuses a requested label that no layer holds.
fn check_labels(map: &LabelMap, labels: &[i64]) -> Result<(), ExtractError> {
    for &value in labels {
        let present = map
            .layers
            .iter()
            .any(|l| l.values.iter().skip(1).any(|&v| v == value));
        if !present {
            let mut all: Vec<i64> = map
                .layers
                .iter()
                .flat_map(|l| l.values.iter().skip(1).copied())
                .collect();
            all.sort_unstable();
            all.dedup();
            let present = all
                .iter()
                .map(|v| v.to_string())
                .collect::<Vec<_>>()
                .join(", ");
            return Err(ExtractError::NoSuchLabel { value, present });
        }
    }
    Ok(())
}

fn code_counts(codes: &[u16], n: usize) -> Vec<usize> {
    // Four counts per code, one per lane: a label map is long runs of one code, and with one
    // count each addition would wait for the one before it.
    let mut lanes = vec![[0usize; 4]; n];
    let quads = codes.chunks_exact(4);
    let rest = quads.remainder();
    for q in quads {
        for (lane, &c) in q.iter().enumerate() {
            lanes[c as usize][lane] += 1;
        }
    }
    for &c in rest {
        lanes[c as usize][0] += 1;
    }
    lanes.iter().map(|l| l.iter().sum()).collect()
}

/// A structure's name and colour: the file's segment, else the table's entry, else the
/// format's convention (FreeSurfer's table for MGH), else (the colour) TotalSegmentator's for
/// its classes, else defaults; and the codes the file gives it, else the standard class's.
fn naming(
    map: &LabelMap,
    names: &[Segment],
    layer: usize,
    value: i64,
    ordinal: usize,
) -> (String, [f32; 3], Option<StructureCodes>) {
    let own = map
        .segments
        .iter()
        .find(|s| s.layer == layer && s.value == value);
    let table = names.iter().find(|s| s.value == value);
    let convention = (map.conventional.iter()).find(|s| s.layer == layer && s.value == value);
    let sources = [own, table, convention];
    let name = (sources.iter().flatten())
        .map(|s| s.name.trim())
        .find(|n| !n.is_empty())
        .map_or_else(|| format!("label {value}"), str::to_string);
    let standard = super::standard_class(&name);
    let color = (sources.iter().flatten())
        .find_map(|s| s.color)
        .or(standard.as_ref().map(|c| c.color))
        .unwrap_or_else(|| default_color(ordinal));
    let codes = (own.and_then(|s| s.codes.clone())).or(standard.map(|c| c.codes));
    (name, color, codes)
}

#[cfg(test)]
mod tests {
    #[test]
    fn codes_are_counted_in_any_run_and_any_length() {
        let codes: Vec<u16> = (0..1003u32).map(|i| ((i / 7) % 5) as u16).collect();
        let mut expected = vec![0usize; 6];
        for &c in &codes {
            expected[c as usize] += 1;
        }
        assert_eq!(super::code_counts(&codes, 6), expected);
        assert_eq!(super::code_counts(&[], 2), [0, 0]);
    }
}
