//! `meshsmooth bench-load FILE`.
use std::path::Path;

pub fn run(_path: &Path, _repeat: usize, _json: bool) -> Result<(), String> {
    Err("bench-load is not available in this build".into())
}
