//! `meshsmooth convert IN OUT`.

use crate::export::{self, ExportFormat, ExportOptions};
use std::path::Path;

/// `millimetres`: a GLB keeps the data's millimetres instead of metres with +Y up.
pub(super) fn run(input: &Path, output: &Path, millimetres: bool) -> Result<(), String> {
    let format = output_format(output)?;
    super::check_destination(output)?;
    let mesh = super::load_file(input)?;
    let options = ExportOptions {
        millimetres,
        ..Default::default()
    };
    let bytes =
        export::write(&mesh, format, &options).map_err(|e| format!("{}: {e}", output.display()))?;
    super::write_file(output, &bytes)
}

/// The output format named by the file's extension.
pub(super) fn output_format(output: &Path) -> Result<ExportFormat, String> {
    ExportFormat::from_name(&output.to_string_lossy()).ok_or_else(|| {
        format!(
            "{}: cannot tell the output format: use .ply, .stl, .obj or .glb",
            output.display()
        )
    })
}
