//! Finds libgmpu and extracts the README's Rust example for `tests/readme.rs`.
//!
//! Library search order (the first that applies wins):
//!   1. `GMPU_LIBRARY`: the library file (libgmpu.so.1), or a directory holding it, as for
//!      the Python and Node bindings (`GMPU_LIB_DIR`, a directory, is still read after it);
//!   2. pkg-config's `gmpu.pc`, if installed (`pkg-config --libs gmpu`, run as a command;
//!      PKG_CONFIG_PATH is honoured);
//!   3. the meson build directory of this source tree, `../../build/lib`.
//!
//! When that directory holds the static library (libgmpu.a: meson builds and installs it
//! beside libgmpu.so), it is linked statically, with the C++ runtime it needs, so every
//! program that depends on this crate, a user's own binary included, runs with no
//! environment variables and no rpath. (An rpath set here would reach only this package's
//! own tests and examples: cargo:rustc-link-arg does not apply to dependents.)
//! GMPU_LINK=dylib links libgmpu.so instead; the crate's tests and examples then get an
//! rpath to it.
use std::env;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

fn has_library(dir: &Path) -> bool {
    ["libgmpu.so", "libgmpu.dylib", "gmpu.lib"].iter().any(|f| dir.join(f).exists())
}

/// `-L` directories and `-l` libraries of `pkg-config --libs gmpu`, or None when pkg-config
/// is missing or has no gmpu.pc.
fn pkg_config() -> Option<(Vec<String>, Vec<String>)> {
    let pkg_config = env::var("PKG_CONFIG").unwrap_or_else(|_| "pkg-config".to_string());
    let out = Command::new(pkg_config).args(["--libs", "gmpu"]).output().ok()?;
    if !out.status.success() {
        return None;
    }
    let text = String::from_utf8(out.stdout).ok()?;
    let mut dirs = Vec::new();
    let mut libs = Vec::new();
    for word in text.split_whitespace() {
        if let Some(d) = word.strip_prefix("-L") {
            dirs.push(d.to_string());
        } else if let Some(l) = word.strip_prefix("-l") {
            libs.push(l.to_string());
        }
    }
    if !libs.iter().any(|l| l == "gmpu") {
        return None;
    }
    Some((dirs, libs))
}

fn links_statically(dir: &str) -> bool {
    let want_dylib = env::var("GMPU_LINK").map(|v| v == "dylib").unwrap_or(false);
    !want_dylib && Path::new(dir).join("libgmpu.a").exists()
}

/// Links libgmpu from `dir`: statically when libgmpu.a is there (unless GMPU_LINK=dylib).
fn link_gmpu(dir: &str) {
    if links_statically(dir) {
        // The archive is copied into every binary: a rebuilt one must relink them.
        println!("cargo:rerun-if-changed={dir}/libgmpu.a");
        println!("cargo:rustc-link-search=native={dir}");
        println!("cargo:rustc-link-lib=static=gmpu");
        // The archive's C++ objects need the C++ runtime (Rust's std links libm and pthread).
        println!("cargo:rustc-link-lib=dylib=stdc++");
        // Mesh simplification comes from the system's meshoptimizer (a shared library on Debian).
        println!("cargo:rustc-link-lib=dylib=meshoptimizer");
        return;
    }
    link_dir(dir);
    println!("cargo:rustc-link-lib=dylib=gmpu");
}

fn link_dir(dir: &str) {
    println!("cargo:rustc-link-search=native={dir}");
    // rpath for everything this package links (tests, examples, binaries); a dependent crate
    // sets its own. DEP_GMPU_ROOT carries the directory to it (links = "gmpu", `cargo:root`).
    if cfg!(target_os = "linux") || cfg!(target_os = "macos") {
        println!("cargo:rustc-link-arg=-Wl,-rpath,{dir}");
    }
}

fn find_library() {
    println!("cargo:rerun-if-env-changed=GMPU_LIBRARY");
    println!("cargo:rerun-if-env-changed=GMPU_LIB_DIR");
    println!("cargo:rerun-if-env-changed=GMPU_LINK");
    println!("cargo:rerun-if-env-changed=PKG_CONFIG_PATH");
    println!("cargo:rerun-if-env-changed=PKG_CONFIG");
    let manifest = PathBuf::from(env::var("CARGO_MANIFEST_DIR").unwrap());

    if let Some(path) = env::var_os("GMPU_LIBRARY").filter(|d| !d.is_empty()) {
        let path = PathBuf::from(path);
        let path = if path.is_relative() { manifest.join(path) } else { path };
        let file = if path.is_dir() { path.join("libgmpu.so.1") } else { path };
        if !file.is_file() {
            panic!("GMPU_LIBRARY={}: no such file (build the library with `make build`)", file.display());
        }
        let file = file.canonicalize().unwrap_or(file);
        let dir = file.parent().unwrap().to_string_lossy().into_owned();
        link_dir(&dir);
        println!("cargo:root={dir}");
        // The file itself, by its name (libgmpu.so.1 has no libgmpu.so beside it when only
        // the runtime library is installed).
        println!("cargo:rustc-link-lib=dylib:+verbatim={}", file.file_name().unwrap().to_string_lossy());
        return;
    }

    if let Some(dir) = env::var_os("GMPU_LIB_DIR").filter(|d| !d.is_empty()) {
        let dir = PathBuf::from(dir);
        let dir = if dir.is_relative() { manifest.join(dir) } else { dir };
        if !has_library(&dir) {
            panic!("GMPU_LIB_DIR={} holds no libgmpu (build it with `make build`)", dir.display());
        }
        let dir = dir.canonicalize().unwrap_or(dir);
        let d = dir.to_string_lossy().into_owned();
        link_gmpu(&d);
        println!("cargo:root={d}");
        return;
    }

    if let Some((dirs, libs)) = pkg_config() {
        if let Some(d) = dirs.iter().find(|d| links_statically(d)) {
            link_gmpu(d);
            println!("cargo:root={d}");
            return;
        }
        for d in &dirs {
            link_dir(d);
        }
        if let Some(d) = dirs.first() {
            println!("cargo:root={d}");
        }
        for l in libs {
            println!("cargo:rustc-link-lib={l}");
        }
        return;
    }

    let build = manifest.join("../../build/lib");
    println!("cargo:rerun-if-changed={}", build.join("libgmpu.so").display());
    if has_library(&build) {
        let dir = build.canonicalize().unwrap_or(build);
        let d = dir.to_string_lossy().into_owned();
        link_gmpu(&d);
        println!("cargo:root={d}");
        return;
    }

    panic!(
        "libgmpu not found: set GMPU_LIBRARY to the path of libgmpu.so.1, install gmpu \
         (meson install, so that `pkg-config --libs gmpu` works), or build it in this tree with \
         `make build` (expected at {})",
        build.display()
    );
}

/// Writes the README's Rust example (the one ```rust block between `<!-- rust:begin -->`
/// and `<!-- rust:end -->`) to OUT_DIR/readme_example.rs for tests/readme.rs. A README
/// without it becomes a compile error in that test, not a silent pass.
fn extract_readme_example() {
    let readme = PathBuf::from(env::var("CARGO_MANIFEST_DIR").unwrap()).join("../../README.md");
    println!("cargo:rerun-if-changed={}", readme.display());
    let out = PathBuf::from(env::var("OUT_DIR").unwrap()).join("readme_example.rs");
    let code = match fs::read_to_string(&readme) {
        Err(e) => Err(format!("cannot read {}: {e}", readme.display())),
        Ok(text) => readme_block(&text),
    };
    let code = code.unwrap_or_else(|why| format!("compile_error!({why:?});\n"));
    fs::write(out, code).expect("write OUT_DIR/readme_example.rs");
}

fn readme_block(text: &str) -> Result<String, String> {
    let begin = text.find("<!-- rust:begin -->").ok_or("README.md has no <!-- rust:begin --> marker")?;
    let end = text[begin..].find("<!-- rust:end -->").ok_or("README.md has no <!-- rust:end --> marker")?;
    let section = &text[begin..begin + end];
    let mut blocks = Vec::new();
    let mut current: Option<String> = None;
    for line in section.lines() {
        let trimmed = line.trim_start();
        match current.as_mut() {
            None if trimmed.starts_with("```rust") => current = Some(String::new()),
            None => {}
            Some(_) if trimmed.starts_with("```") => blocks.push(current.take().unwrap()),
            Some(code) => {
                code.push_str(line);
                code.push('\n');
            }
        }
    }
    match blocks.len() {
        1 => Ok(blocks.pop().unwrap()),
        0 => Err("the README's Rust section has no ```rust block".into()),
        n => Err(format!("the README's Rust section has {n} ```rust blocks; expected exactly one program")),
    }
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    find_library();
    extract_readme_example();
}
