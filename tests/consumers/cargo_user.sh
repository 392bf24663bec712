#!/bin/bash
# A user's own program on the Rust crate, as the README shows: `cargo new`, a path
# dependency on bindings/rust, `cargo run`, with no GMPU_* or LD_LIBRARY_PATH in the
# environment. build.rs links libgmpu.a statically, so the binary needs no libgmpu.so.
# Offline: the crate has no dependencies. Needs `make build` first (build/lib).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
crate=$(cd "$here/../../bindings/rust" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/gmpu-cargo-user.XXXXXX")
trap 'rm -rf "$work"' EXIT

clean_env=(env -u GMPU_LIB_DIR -u GMPU_LINK -u GMPU_LIBRARY -u LD_LIBRARY_PATH -u PKG_CONFIG_PATH
           CARGO_TARGET_DIR="$work/target")
cd "$work"
"${clean_env[@]}" cargo new --quiet --vcs none my_app
cd my_app
cat >> Cargo.toml <<TOML
gmpu = { path = "$crate" }
TOML
cat > src/main.rs <<'RUST'
fn main() -> Result<(), gmpu::Error> {
    // A Fibonacci sphere of 800 points, reconstructed.
    let n = 800;
    let points: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let a = 2.399963229728653 * i as f64;
            [r * a.cos(), r * a.sin(), z]
        })
        .collect();
    let mesh = gmpu::reconstruct(&points, &[(gmpu::Param::Resolution, 24.0)])?;
    println!("{} triangles", mesh.triangles().len());
    Ok(())
}
RUST
"${clean_env[@]}" cargo build --offline --quiet
binary=$work/target/debug/my_app
if [[ $(readelf -d "$binary") == *NEEDED*libgmpu* ]]; then
    echo "cargo_user: the binary needs libgmpu.so; expected it linked statically" >&2
    exit 1
fi
out=$("${clean_env[@]}" "$binary")
[[ $out =~ ^[1-9][0-9]*\ triangles$ ]] || { echo "cargo_user: printed '$out'" >&2; exit 1; }
echo "cargo_user: ok ($out)"
