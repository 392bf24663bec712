//! Runs the crate's example CLI (examples/reconstruct.rs, built by `cargo test`).
mod common;

use std::path::PathBuf;
use std::process::Command;

use common::*;

fn example() -> PathBuf {
    // target/<profile>/deps/example-HASH → target/<profile>/examples/reconstruct
    let exe = std::env::current_exe().unwrap();
    let path = exe.parent().unwrap().parent().unwrap().join("examples").join("reconstruct");
    assert!(
        path.exists(),
        "example binary not built at {} (plain `cargo test` builds the examples; with a target filter run `cargo build --examples` first)",
        path.display()
    );
    path
}

#[test]
fn reconstructs_the_sample() {
    let out = temp_path("example", "bunny.ply");
    let normals = temp_path("example", "bunny_points.ply");
    let run = Command::new(example())
        .arg(sample())
        .arg(&out)
        .args(["--resolution", "32", "--threads", "2", "--normals-out"])
        .arg(&normals)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "exit {:?}: {stderr}", run.status);
    assert!(stderr.contains("35000 points") && stderr.contains("resolution 32"), "{stderr}");
    let mesh = gmpu::Points::read(&out).unwrap();
    assert!(mesh.len() > 1000);
    let oriented = gmpu::Points::read(&normals).unwrap();
    assert_eq!(oriented.len(), 35_000);
    assert!(oriented.normals().is_some());
    remove_temp_dir("example");
}

#[test]
fn reports_usage_and_failures() {
    let run = Command::new(example()).output().unwrap();
    assert_eq!(run.status.code(), Some(2), "no arguments is a usage error");
    let run = Command::new(example()).args(["in.ply", "out.ply", "--resolution", "abc"]).output().unwrap();
    assert_eq!(run.status.code(), Some(2));
    let out = temp_path("example_fail", "never.ply");
    let run = Command::new(example()).arg("/nonexistent/cloud.ply").arg(&out).output().unwrap();
    assert_eq!(run.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(stderr.contains("GMPU_ERROR_IO"), "{stderr}");
    let run = Command::new(example()).args(["in.ply", "out.ply", "--sharp", "--bogus"]).output().unwrap();
    assert_eq!(run.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&run.stderr).contains("unknown option '--bogus'"));
    let run = Command::new(example()).arg(sample()).arg(&out).args(["--resolution", "5", "-q"]).output().unwrap();
    assert_eq!(run.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&run.stderr).contains("GMPU_PARAM_RESOLUTION"));
    assert!(!out.exists());
    remove_temp_dir("example_fail");
}
