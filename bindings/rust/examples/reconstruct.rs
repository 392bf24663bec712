//! reconstruct — unoriented point cloud in, watertight oriented mesh out (the Rust twin of
//! the C CLI `gmpu-reconstruct`).
//!
//!     cargo run --example reconstruct -- IN.ply OUT.ply [--error E] [--max-depth D]
//!         [--resolution R] [--level L] [--threads T] [--sharp | --no-sharp] [--use-normals]
//!         [--normals-out POINTS.ply] [--quiet]
//!
//! The output format comes from OUT's extension (.ply, .obj, .off). Exit status 0 on
//! success, 1 on a failure (one line on stderr), 2 on bad usage.
use std::process::ExitCode;

use gmpu::{ControlFlow, Param, Points, Stage, Stat, Surface};

const USAGE: &str = "usage: reconstruct IN OUT [--error E] [--max-depth D] [--resolution R] [--level L]
                   [--threads T] [--sharp | --no-sharp] [--use-normals] [--normals-out POINTS.ply] [--quiet]
  IN   .ply .xyz .txt .off .obj point cloud (normals ignored unless --use-normals)
  OUT  .ply .obj .off mesh (closed, outward-facing)";

#[derive(Default)]
struct Options {
    input: Option<String>,
    output: Option<String>,
    normals_out: Option<String>,
    params: Vec<(Param, f64)>,
    use_normals: bool,
    quiet: bool,
}

fn parse_args(args: &[String]) -> Result<Options, String> {
    let mut o = Options::default();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = |flag: &str| -> Result<f64, String> {
            let text = it.next().ok_or_else(|| format!("{flag} needs a number"))?;
            text.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("{flag} needs a number, got '{text}'"))
        };
        match a.as_str() {
            "-h" | "--help" => {
                println!("{USAGE}");
                std::process::exit(0);
            }
            "--error" => o.params.push((Param::Error, value(a)?)),
            "--max-depth" => o.params.push((Param::MaxDepth, value(a)?)),
            "--resolution" => o.params.push((Param::Resolution, value(a)?)),
            "--level" => o.params.push((Param::Level, value(a)?)),
            "--threads" => o.params.push((Param::Threads, value(a)?)),
            "--sharp" => o.params.push((Param::SharpFeatures, 1.0)),
            "--no-sharp" => o.params.push((Param::SharpFeatures, 0.0)),
            "--use-normals" => o.use_normals = true,
            "--quiet" | "-q" => o.quiet = true,
            "-o" | "--output" | "--normals-out" => {
                let path = it.next().ok_or_else(|| format!("{a} needs a path"))?.clone();
                if a == "--normals-out" {
                    o.normals_out = Some(path);
                } else {
                    o.output = Some(path);
                }
            }
            flag if flag.starts_with('-') && flag.len() > 1 => return Err(format!("unknown option '{flag}'")),
            _ if o.input.is_none() => o.input = Some(a.clone()),
            _ if o.output.is_none() => o.output = Some(a.clone()),
            _ => return Err(format!("unexpected argument '{a}'")),
        }
    }
    if o.input.is_none() || o.output.is_none() {
        return Err(if o.input.is_none() { "missing IN" } else { "missing OUT" }.into());
    }
    Ok(o)
}

/// `map_err` adapter: "what: GMPU_ERROR_…: reason".
fn fail(what: &'static str) -> impl Fn(gmpu::Error) -> String {
    move |e| format!("{what}: {e}")
}

fn run(o: &Options) -> Result<(), String> {
    let input = o.input.as_deref().unwrap();
    let output = o.output.as_deref().unwrap();

    let cloud = Points::read(input).map_err(fail("cannot read input"))?;
    let mut surface = Surface::new().map_err(fail("cannot create surface"))?;
    surface.set_params(&o.params).map_err(fail("bad parameter"))?;
    if !o.quiet {
        let mut current = None;
        surface
            .set_progress(move |stage: Stage, _fraction| {
                if current != Some(stage) {
                    current = Some(stage);
                    eprintln!("gmpu: {}...", format!("{stage:?}").to_lowercase());
                }
                ControlFlow::Continue(())
            })
            .map_err(fail("cannot set progress"))?;
    }
    surface.set_points(cloud.positions()).map_err(fail("bad input points"))?;
    if o.use_normals {
        let normals = cloud.normals().ok_or_else(|| format!("--use-normals given but {input} has no normals"))?;
        surface.set_normals(normals).map_err(fail("bad input normals"))?;
    }
    surface.fit().map_err(fail("fit failed"))?;
    surface.orient().map_err(fail("orient failed"))?;
    let mesh = surface.polygonize().map_err(fail("polygonize failed"))?;
    mesh.write(output).map_err(fail("cannot write mesh"))?;
    if let Some(path) = &o.normals_out {
        let written =
            surface.normals().and_then(|n| Points::new(cloud.positions(), Some(&n))).and_then(|p| p.write(path));
        if let Err(e) = written {
            let _ = std::fs::remove_file(output); // all or nothing, as the C CLI
            return Err(format!("cannot write oriented points: {e}"));
        }
    }
    if !o.quiet {
        let stat = |k| surface.stat(k).unwrap_or(f64::NAN);
        eprintln!(
            "gmpu: {} points, {} cells ({} leaves, depth {}), {} component(s)",
            cloud.len(),
            stat(Stat::Cells),
            stat(Stat::Leaves),
            stat(Stat::Depth),
            stat(Stat::Components)
        );
        eprintln!(
            "gmpu: mesh {} vertices, {} triangles at resolution {} -> {output}",
            mesh.vertex_count(),
            mesh.triangle_count(),
            stat(Stat::Resolution)
        );
    }
    Ok(())
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let options = match parse_args(&args) {
        Ok(o) => o,
        Err(why) => {
            eprintln!("reconstruct: {why}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    match run(&options) {
        Ok(()) => ExitCode::SUCCESS,
        Err(why) => {
            eprintln!("reconstruct: {why}");
            ExitCode::from(1)
        }
    }
}
