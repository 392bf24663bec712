//! Helpers shared by the integration tests: data paths, synthetic clouds, mesh checks.
#![allow(dead_code)]
use std::collections::HashMap;
use std::path::PathBuf;

pub fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The sample cloud shipped in the repository (35,000 points of the Stanford bunny).
pub fn sample() -> PathBuf {
    repo_root().join("examples/data/bunny.ply")
}

/// The test data directory: GMPU_TEST_DATA, else `tests/data` of this checkout.
/// Missing data is a failure, not a skip.
pub fn test_data() -> PathBuf {
    let dir = match std::env::var_os("GMPU_TEST_DATA") {
        Some(d) => PathBuf::from(d),
        None => repo_root().join("tests/data"),
    };
    assert!(dir.join("clouds").is_dir(), "test data not found at {} (set GMPU_TEST_DATA)", dir.display());
    dir
}

/// This test's own temporary directory, `$TMPDIR/gmpu-rust-PID-TEST` (created).
pub fn temp_dir(test: &str) -> PathBuf {
    assert!(!test.is_empty() && !test.contains(['/', '.']), "bad test name {test:?}");
    let dir = std::env::temp_dir().join(format!("gmpu-rust-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A file path in this test's temporary directory.
pub fn temp_path(test: &str, file: &str) -> PathBuf {
    assert!(!file.is_empty() && !file.contains('/'), "bad file name {file:?}");
    temp_dir(test).join(file)
}

/// Removes this test's temporary directory, and nothing else: only a directory named
/// `gmpu-rust-PID-TEST` directly inside the system temporary directory.
pub fn remove_temp_dir(test: &str) {
    let dir = std::env::temp_dir().join(format!("gmpu-rust-{}-{test}", std::process::id()));
    let name = dir.file_name().and_then(|n| n.to_str()).unwrap_or_default();
    assert!(name.starts_with("gmpu-rust-") && dir.parent() == Some(std::env::temp_dir().as_path()));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `n` points on a sphere (Fibonacci lattice), centre `c`, radius `r`.
pub fn sphere(n: usize, c: [f64; 3], r: f64) -> Vec<[f64; 3]> {
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let s = (1.0 - z * z).sqrt();
            let a = i as f64 * 2.399963229728653;
            [c[0] + r * s * a.cos(), c[1] + r * s * a.sin(), c[2] + r * z]
        })
        .collect()
}

/// Closed and consistently wound: every undirected edge in exactly two triangles, every
/// directed edge in exactly one, no triangle repeating a vertex, every index in range.
pub fn check_watertight(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<(), String> {
    if triangles.is_empty() {
        return Err("no triangles".into());
    }
    let mut undirected: HashMap<(u32, u32), u32> = HashMap::new();
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    for (t, tri) in triangles.iter().enumerate() {
        if tri.iter().any(|&v| v as usize >= vertices.len()) {
            return Err(format!("triangle {t} {tri:?} indexes past {} vertices", vertices.len()));
        }
        if tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] {
            return Err(format!("triangle {t} {tri:?} repeats a vertex"));
        }
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            *undirected.entry((a.min(b), a.max(b))).or_default() += 1;
            *directed.entry((a, b)).or_default() += 1;
        }
    }
    if let Some((e, n)) = undirected.iter().find(|(_, &n)| n != 2) {
        let bad = undirected.values().filter(|&&n| n != 2).count();
        return Err(format!("{bad} edges not used exactly twice, e.g. {e:?} used {n} times"));
    }
    if let Some((e, n)) = directed.iter().find(|(_, &n)| n != 1) {
        return Err(format!("inconsistent winding: directed edge {e:?} used {n} times"));
    }
    Ok(())
}

/// Signed volume enclosed by a closed mesh (positive when wound counter-clockwise seen from
/// outside).
pub fn signed_volume(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Share of normals agreeing in sign with the ground truth (no global flip allowed).
pub fn orientation_accuracy(normals: &[[f64; 3]], truth: &[[f64; 3]]) -> f64 {
    assert_eq!(normals.len(), truth.len());
    let good = normals.iter().zip(truth).filter(|(n, t)| dot(**n, **t) > 0.0).count();
    good as f64 / normals.len() as f64
}

/// `MaxDepth` → `MAX_DEPTH`: a Rust variant's name spelled as the C enumerator's tail.
pub fn screaming(camel: &str) -> String {
    let mut out = String::new();
    for (i, c) in camel.chars().enumerate() {
        if c.is_uppercase() && i > 0 {
            out.push('_');
        }
        out.push(c.to_ascii_uppercase());
    }
    out
}
