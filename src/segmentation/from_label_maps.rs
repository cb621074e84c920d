//! Opening a segmentation from files: one label map (each label a structure), or several files:
//! binary masks (each file a structure, named by its file name, as TotalSegmentator writes them)
//! and files that name their own segments (a folder of DICOM SEG objects), with an optional
//! colour table that names the labels. Shared by the CLI and the page.

use super::{extract, ExtractError, ExtractOptions, Structure};
use crate::io::{self, LabelMap, LabelMapOptions, LoadError, Segment};

/// A file's name and bytes.
#[derive(Clone, Copy, Debug)]
pub struct NamedBytes<'a> {
    pub name: &'a str,
    pub bytes: &'a [u8],
}

/// How to open a segmentation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OpenOptions {
    pub extract: ExtractOptions,
    /// The level at which float images become masks (default 0.5).
    pub level: Option<f64>,
}

/// Why a segmentation could not be opened; each names the file at fault.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OpenError {
    #[error("{name}: {error}")]
    Load { name: String, error: LoadError },
    #[error("{name}: {error}")]
    Extract { name: String, error: ExtractError },
    #[error("no label map given")]
    NoFiles,
    #[error("--labels picks labels of one label map; with several mask files each file is one structure")]
    LabelsWithMasks,
}

/// The stages of reading one label map.
const ONE_MAP: [&str; 2] = ["reading the label map", "extracting the structures"];
/// The stages of reading each of several files (masks, or SEGs that name their segments), one
/// after another: announced before a file is read, so they name no kind of file.
const EACH_FILE: [&str; 2] = ["reading a file", "extracting its structures"];

/// The stages [`open_staged`] announces for `maps` label-map files, in order.
pub fn reading_stages(maps: usize) -> Vec<&'static str> {
    match maps {
        0 => Vec::new(),
        1 => ONE_MAP.to_vec(),
        n => EACH_FILE.repeat(n),
    }
}

/// Reads the files and extracts their structures. One file: a label map, its labels named by
/// the file, else by `table`, else `label N`. Several: a file that names its segments (DICOM
/// SEG, `.seg.nrrd`) gives each its structure, any other is a mask (every non-zero voxel), one
/// structure named by the file; each keeps its own grid, and labels number the structures.
pub fn open(
    files: &[NamedBytes],
    table: Option<NamedBytes>,
    options: &OpenOptions,
) -> Result<Vec<Structure>, OpenError> {
    open_staged(files, table, options, &mut |_| {})
}

/// [`open`], telling `on_stage` each of [`reading_stages`] as it begins. Masks are read and
/// extracted one at a time, so only one mask's voxels are in memory at once.
pub fn open_staged(
    files: &[NamedBytes],
    table: Option<NamedBytes>,
    options: &OpenOptions,
    on_stage: &mut dyn FnMut(&'static str),
) -> Result<Vec<Structure>, OpenError> {
    let read_options = LabelMapOptions {
        level: options.level,
    };
    let names = match table {
        Some(t) => io::parse_color_table(t.bytes)
            .map_err(|error| OpenError::Load {
                name: t.name.to_string(),
                error,
            })?
            .into_iter()
            .map(|e| Segment {
                layer: 0,
                value: e.value,
                name: e.name,
                color: e.color,
                codes: None,
            })
            .collect(),
        None => Vec::new(),
    };
    let read = |f: &NamedBytes| {
        io::load_label_map(f.bytes, f.name, &read_options).map_err(|error| OpenError::Load {
            name: f.name.to_string(),
            error,
        })
    };
    let extract_from = |f: &NamedBytes, map: &LabelMap, o: &ExtractOptions| {
        extract(map, &names, o).map_err(|error| OpenError::Extract {
            name: f.name.to_string(),
            error,
        })
    };
    match files {
        [] => Err(OpenError::NoFiles),
        [one] => {
            on_stage(ONE_MAP[0]);
            let map = read(one)?;
            on_stage(ONE_MAP[1]);
            extract_from(one, &map, &options.extract)
        }
        several => {
            if !options.extract.labels.is_empty() {
                return Err(OpenError::LabelsWithMasks);
            }
            let mut out = Vec::with_capacity(several.len());
            for (ordinal, f) in several.iter().enumerate() {
                on_stage(EACH_FILE[0]);
                let map = read(f)?;
                if !map.segments.is_empty() {
                    on_stage(EACH_FILE[1]);
                    for mut s in extract_from(f, &map, &options.extract)? {
                        s.label = out.len() as i64 + 1;
                        out.push(s);
                    }
                    continue;
                }
                let map = as_mask(map);
                on_stage(EACH_FILE[1]);
                for mut s in extract_from(f, &map, &options.extract)? {
                    s.label = out.len() as i64 + 1;
                    s.name = structure_name(f.name);
                    let standard = super::standard_class(&s.name);
                    s.color = (standard.as_ref())
                        .map_or_else(|| super::default_color(ordinal), |c| c.color);
                    s.codes = standard.map(|c| c.codes);
                    out.push(s);
                }
            }
            Ok(out)
        }
    }
}

/// Every labelled voxel of every layer as one label, 1.
fn as_mask(mut map: LabelMap) -> LabelMap {
    let mut layers = std::mem::take(&mut map.layers).into_iter();
    if let Some(mut first) = layers.next() {
        for c in &mut first.codes {
            *c = u16::from(*c != 0);
        }
        for layer in layers {
            for (c, &o) in first.codes.iter_mut().zip(&layer.codes) {
                *c |= u16::from(o != 0);
            }
        }
        first.values = vec![0, 1];
        map.layers = vec![first];
    }
    map.segments.clear();
    map
}

/// A structure's name from its file's, as TotalSegmentator names its masks: the folder and the
/// label-map extensions dropped, read as words (`portal_vein.nii.gz` is "Portal vein",
/// `kidney_left.nii.gz` "Left kidney").
pub fn structure_name(file: &str) -> String {
    let base = file.rsplit(['/', '\\']).next().unwrap_or(file);
    let lower = base.to_ascii_lowercase();
    let stem_len = [
        ".seg.nrrd",
        ".nii.gz",
        ".nii",
        ".nrrd",
        ".nhdr",
        ".mgz",
        ".mgh",
        ".dcm",
    ]
    .iter()
    .find(|ext| lower.ends_with(*ext))
    .map_or(base.len(), |ext| base.len() - ext.len());
    io::readable_class_name(base[..stem_len].trim())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_come_from_file_names() {
        assert_eq!(structure_name("out/portal_vein.nii.gz"), "Portal vein");
        assert_eq!(
            structure_name("segmentations/kidney_left.nii.gz"),
            "Left kidney"
        );
        assert_eq!(structure_name("C:\\seg\\Liver.NII"), "Liver");
        assert_eq!(structure_name("case.seg.nrrd"), "Case");
        assert_eq!(structure_name("tumour"), "Tumour");
    }
}
