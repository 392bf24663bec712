//! Compiles and runs the Rust example of the top-level README.md (the one ```rust block
//! between `<!-- rust:begin -->` and `<!-- rust:end -->`, extracted by build.rs). A README
//! without that block fails to compile this test.
include!(concat!(env!("OUT_DIR"), "/readme_example.rs"));

#[test]
fn readme_rust_example_runs() {
    // The example uses paths relative to the repository root, as a reader would run it.
    std::env::set_current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).unwrap();
    let out = std::env::temp_dir().join("bunny_mesh.ply");
    let _ = std::fs::remove_file(&out);
    let result: Result<(), gmpu::Error> = main();
    result.expect("the README example failed");
    assert!(out.exists(), "the README example did not write {}", out.display());
    let mesh = gmpu::Points::read(&out).unwrap();
    assert!(mesh.len() > 1000);
    let _ = std::fs::remove_file(&out);
}
