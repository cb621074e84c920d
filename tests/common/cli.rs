//! Running the built CLI from an integration test: its output, its JSON, a scratch folder.

use std::path::PathBuf;
use std::process::{Command, Output};

/// A path below ../shared/data.
pub fn data(rel: &str) -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data")).join(rel)
}

pub fn meshsmooth(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_meshsmooth"))
        .args(args)
        .output()
        .expect("the meshsmooth binary runs")
}

/// Stdout as JSON; fails the test with stderr when the command failed.
pub fn json(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("stdout is JSON")
}

/// A path in this test process's scratch folder.
pub fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("meshsmooth-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir.join(name)
}
