//! Keeps `gmpu::sys` (and the safe enums) in sync with `include/gmpu/gmpu.h`, through the
//! ABI summary `bindings/abi.txt` that `bindings/python/tools/generate_cdef.py` generates
//! from the header (the Python tests fail when the summary is stale): its function
//! prototypes, the progress-callback typedef, the opaque handles, the struct fields, the
//! enum values and the version defines are compared with what `sys` declares. Any
//! function, parameter (type or name), return type, field, enumerator or value that differs
//! fails the test. The summary is `../abi.txt`, or `GMPU_ABI_SUMMARY` if set.
mod common;
use std::collections::BTreeMap;
use std::path::PathBuf;

use gmpu::sys;

fn summary_path() -> PathBuf {
    match std::env::var_os("GMPU_ABI_SUMMARY") {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../abi.txt"),
    }
}

fn summary_text() -> String {
    let path = summary_path();
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read the ABI summary {}: {e}", path.display()))
}

#[derive(Debug, Default)]
struct Header {
    functions: BTreeMap<String, (Vec<(String, String)>, String)>, // name → ([(param, rust type)], rust ret)
    enums: BTreeMap<String, Vec<(String, u32)>>,
    opaque: Vec<String>,
    structs: BTreeMap<String, Vec<(String, String)>>, // name → [(field, rust type)]
    progress_fn: Option<(Vec<String>, String)>,
    defines: BTreeMap<String, u32>,
}

/// The tokens of a C type as the summary spells it (`gmpu_surface **` → gmpu_surface * *).
fn c_tokens(c: &str) -> Vec<String> {
    c.replace('*', " * ").split_whitespace().map(String::from).collect()
}

/// The Rust spelling of a C type given as tokens (`const double *` → `*const f64`).
fn rust_type(c: &[String]) -> String {
    let mut base_const = false;
    let mut base = None;
    let mut i = 0;
    while i < c.len() && c[i] != "*" {
        match c[i].as_str() {
            "const" => base_const = true,
            "struct" | "enum" => {}
            t => {
                assert!(base.is_none(), "unexpected type {c:?}");
                base = Some(t.to_string());
            }
        }
        i += 1;
    }
    let base = base.unwrap_or_else(|| panic!("no base type in {c:?}"));
    let mut ty = match base.as_str() {
        "void" => if i < c.len() { "c_void" } else { "()" }.to_string(),
        "char" => "c_char".into(),
        "int" => "c_int".into(),
        "unsigned" => "c_uint".into(),
        "double" => "f64".into(),
        "float" => "f32".into(),
        "size_t" => "usize".into(),
        "uint32_t" => "u32".into(),
        "int32_t" => "i32".into(),
        "uint64_t" => "u64".into(),
        "int64_t" => "i64".into(),
        "uint8_t" => "u8".into(),
        t if t.starts_with("gmpu_") => t.to_string(),
        t => panic!("C type {t} has no mapping in header_sync.rs"),
    };
    let mut pointee_const = base_const;
    while i < c.len() {
        assert_eq!(c[i], "*", "unexpected token in type {c:?}");
        ty = format!("*{} {}", if pointee_const { "const" } else { "mut" }, ty);
        i += 1;
        pointee_const = i < c.len() && c[i] == "const";
        if pointee_const {
            i += 1;
        }
    }
    ty
}

/// `(name, rust type)` of each `name:C type` field of a summary line.
fn params(fields: &[&str]) -> Vec<(String, String)> {
    fields
        .iter()
        .map(|f| {
            let (name, ty) = f.split_once(':').unwrap_or_else(|| panic!("parameter {f:?} is not name:type"));
            (name.to_string(), rust_type(&c_tokens(ty)))
        })
        .collect()
}

fn parse_summary(text: &str) -> Header {
    let mut h = Header::default();
    for line in text.lines().filter(|l| !l.starts_with('#') && !l.is_empty()) {
        let f: Vec<&str> = line.split('\t').collect();
        let value = |s: &str| s.parse::<u32>().unwrap_or_else(|_| panic!("not a number in {line:?}"));
        match f.as_slice() {
            ["define", name, v] => {
                h.defines.insert(name.to_string(), value(v));
            }
            ["opaque", name] => h.opaque.push(name.to_string()),
            ["enum", ty, name, v] => h.enums.entry(ty.to_string()).or_default().push((name.to_string(), value(v))),
            ["field", ty, name, c] => {
                h.structs.entry(ty.to_string()).or_default().push((name.to_string(), rust_type(&c_tokens(c))))
            }
            ["fn", name, ret, ps @ ..] => {
                let entry = (params(ps), rust_type(&c_tokens(ret)));
                assert!(h.functions.insert(name.to_string(), entry).is_none(), "{name} declared twice");
            }
            ["callback", name, ret, ps @ ..] => {
                assert_eq!(*name, "gmpu_progress_fn", "new function-pointer typedef {name}: add it to sys");
                h.progress_fn = Some((params(ps).into_iter().map(|(_, ty)| ty).collect(), rust_type(&c_tokens(ret))));
            }
            _ => panic!("unknown summary line {line:?}"),
        }
    }
    h
}

fn norm(rust_ty: &str) -> String {
    let s: String = rust_ty.chars().filter(|c| !c.is_whitespace()).collect();
    s.replace("std::os::raw::", "").replace("core::ffi::", "").replace("std::ffi::", "")
}

/// Every difference between the header and the binding, in words.
fn differences(summary: &str) -> Vec<String> {
    let h = parse_summary(summary);
    let mut diffs = Vec::new();

    // Functions, both ways.
    let sys_fns: BTreeMap<&str, &sys::Signature> = sys::FUNCTIONS.iter().map(|s| (s.name, s)).collect();
    for (name, (ps, ret)) in &h.functions {
        let Some(s) = sys_fns.get(name.as_str()) else {
            diffs.push(format!("{name} is in the header but not in sys"));
            continue;
        };
        if norm(s.ret) != norm(ret) {
            diffs.push(format!("{name} returns {ret} in the header, {} in sys", s.ret));
        }
        if s.params.len() != ps.len() {
            diffs.push(format!("{name} takes {} parameters in the header, {} in sys", ps.len(), s.params.len()));
            continue;
        }
        for (k, ((pname, pty), sty)) in ps.iter().zip(s.params).enumerate() {
            if norm(sty) != norm(pty) {
                diffs.push(format!("{name} parameter {k} ({pname}) is {pty} in the header, {sty} in sys"));
            }
        }
    }
    for name in sys_fns.keys() {
        if !h.functions.contains_key(*name) {
            diffs.push(format!("{name} is in sys but not in the header"));
        }
    }

    // Parameter names: the header's, in order (a swapped count/stride keeps the types).
    let src = include_str!("../src/sys.rs");
    for (name, (ps, _)) in &h.functions {
        let Some(at) = src.find(&format!("pub fn {name}(")) else { continue };
        let decl = &src[at..at + src[at..].find(';').unwrap()];
        let names: Vec<String> = ps.iter().map(|(n, _)| n.clone()).collect();
        let open = decl.find('(').unwrap();
        let close = decl.rfind(')').unwrap();
        let inner = &decl[open + 1..close];
        let sys_names: Vec<String> = inner
            .split(',')
            .filter_map(|p| p.split(':').next().map(|n| n.trim().trim_end_matches('_').to_string()))
            .filter(|n| !n.is_empty())
            .collect();
        if sys_names != names {
            diffs.push(format!("{name} parameters are named {names:?} in the header, {sys_names:?} in sys"));
        }
    }
    // Every `fn gmpu_…` in sys.rs goes through the table-making macro.
    for line in src.lines() {
        if let Some(rest) = line.trim_start().strip_prefix("pub fn gmpu_") {
            let name = format!("gmpu_{}", &rest[..rest.find('(').unwrap()]);
            if !sys_fns.contains_key(name.as_str()) {
                diffs.push(format!("{name} is declared in sys.rs outside c_functions!"));
            }
        }
    }

    // Progress callback typedef.
    match &h.progress_fn {
        None => diffs.push("gmpu_progress_fn typedef not found in the header".into()),
        Some((ps, ret)) => {
            let p = sys::PROGRESS_FN;
            let sys_ps: Vec<String> = p.params.iter().map(|t| norm(t)).collect();
            let h_ps: Vec<String> = ps.iter().map(|t| norm(t)).collect();
            if sys_ps != h_ps || norm(p.ret) != norm(ret) {
                diffs.push(format!("gmpu_progress_fn is ({h_ps:?}) -> {ret} in the header, {p:?} in sys"));
            }
        }
    }

    // Opaque handles.
    let mut ho = h.opaque.clone();
    ho.sort();
    let mut so: Vec<String> = sys::OPAQUE_TYPES.iter().map(|s| s.to_string()).collect();
    so.sort();
    if ho != so {
        diffs.push(format!("opaque handles: header {ho:?}, sys {so:?}"));
    }

    // Struct fields, in order, from sys.rs's `pub struct NAME { pub field: type, ... }`.
    for (name, fields) in &h.structs {
        let Some(at) = src.find(&format!("pub struct {name} {{")) else {
            diffs.push(format!("struct {name} is in the header but not in sys"));
            continue;
        };
        let body = &src[at..at + src[at..].find('}').unwrap()];
        let sys_fields: Vec<(String, String)> = body
            .lines()
            .filter_map(|l| l.trim().strip_prefix("pub "))
            .filter_map(|l| l.trim_end_matches(',').split_once(':'))
            .map(|(n, t)| (n.trim().trim_end_matches('_').to_string(), norm(t)))
            .collect();
        let want: Vec<(String, String)> = fields.iter().map(|(n, t)| (n.clone(), norm(t))).collect();
        if sys_fields != want {
            diffs.push(format!("struct {name}: header {want:?}, sys {sys_fields:?}"));
        }
    }

    // Enums, both ways, with values.
    let sys_enums: BTreeMap<&str, &sys::EnumDecl> = sys::ENUMS.iter().map(|e| (e.name, e)).collect();
    for (name, values) in &h.enums {
        match sys_enums.get(name.as_str()) {
            None => diffs.push(format!("enum {name} is in the header but not in sys")),
            Some(e) => {
                let sv: Vec<(String, u32)> = e.values.iter().map(|(n, v)| (n.to_string(), *v)).collect();
                if &sv != values {
                    diffs.push(format!("enum {name}: header {values:?}, sys {sv:?}"));
                }
            }
        }
    }
    for name in sys_enums.keys() {
        if !h.enums.contains_key(*name) {
            diffs.push(format!("enum {name} is in sys but not in the header"));
        }
    }

    // The safe enums cover every enumerator, under the matching name and value.
    let header_enum = |name: &str| h.enums.get(name).cloned().unwrap_or_default();
    let check_safe = |diffs: &mut Vec<String>, prefix: &str, c_enum: &str, safe: Vec<(String, u32)>| {
        let mut want = header_enum(c_enum);
        want.retain(|(n, _)| n != "GMPU_OK");
        let got: Vec<(String, u32)> =
            safe.into_iter().map(|(n, v)| (format!("{prefix}{}", common::screaming(&n)), v)).collect();
        if got != want {
            diffs.push(format!("safe enum for {c_enum}: header {want:?}, binding {got:?}"));
        }
    };
    check_safe(
        &mut diffs,
        "GMPU_PARAM_",
        "gmpu_param",
        gmpu::Param::ALL.iter().map(|p| (format!("{p:?}"), p.to_raw())).collect(),
    );
    check_safe(
        &mut diffs,
        "GMPU_STAT_",
        "gmpu_stat",
        gmpu::Stat::ALL.iter().map(|p| (format!("{p:?}"), p.to_raw())).collect(),
    );
    check_safe(
        &mut diffs,
        "GMPU_ERROR_",
        "gmpu_status",
        gmpu::Status::ALL.iter().map(|s| (format!("{s:?}"), s.to_raw())).collect(),
    );
    let stages: Vec<(String, u32)> = header_enum("gmpu_stage")
        .iter()
        .map(|(_, v)| (format!("{:?}", gmpu::Stage::from_raw(*v)), gmpu::Stage::from_raw(*v).to_raw()))
        .collect();
    check_safe(&mut diffs, "GMPU_STAGE_", "gmpu_stage", stages);

    // #defines.
    for (name, value) in sys::DEFINES {
        match h.defines.get(*name) {
            Some(v) if v == value => {}
            other => diffs.push(format!("#define {name}: header {other:?}, sys {value}")),
        }
    }
    for name in h.defines.keys().filter(|n| n.starts_with("GMPU_") && n.contains("VERSION")) {
        if !sys::DEFINES.iter().any(|(n, _)| n == name) {
            diffs.push(format!("#define {name} is in the header but not in sys"));
        }
    }
    diffs
}

#[test]
fn sys_matches_header() {
    let diffs = differences(&summary_text());
    assert!(diffs.is_empty(), "gmpu::sys differs from {}:\n  {}", summary_path().display(), diffs.join("\n  "));
}

/// Every declared function resolves in the library this crate links (taking the addresses
/// makes the linker look each one up).
#[test]
fn library_exports_every_declared_function() {
    let addresses = sys::function_addresses();
    assert_eq!(addresses.len(), sys::FUNCTIONS.len());
    for (name, address) in addresses {
        assert_ne!(address, 0, "{name}");
    }
}

#[test]
fn summary_holds_the_whole_header() {
    let h = parse_summary(&summary_text());
    assert!(h.functions.len() >= 40, "only {} prototypes in the summary", h.functions.len());
    assert_eq!(h.enums.len(), 5, "{:?}", h.enums.keys());
    assert_eq!(h.functions["gmpu_surface_set_points_f32"].0[1], ("xyz".into(), "*const f32".into()));
    assert_eq!(h.functions["gmpu_surface_create"].0[0].1, "*mut *mut gmpu_surface");
    assert_eq!(h.functions["gmpu_surface_destroy"].1, "()");
}

/// The comparison must notice drift: each edit of the real header below is a change that
/// sys does not have, and must be reported.
#[test]
fn drift_is_detected() {
    let text = summary_text();
    let edits: &[(&str, &str)] = &[
        ("GMPU_PARAM_NOISE_SCALE\t11", "GMPU_PARAM_NOISE_SCALE\t12"),
        ("GMPU_PARAM_MAX_MEMORY\t12\n", "GMPU_PARAM_MAX_MEMORY\t12\nenum\tgmpu_param\tGMPU_PARAM_NEW\t13\n"),
        ("GMPU_STAGE_POLYGONIZE\t3\n", "GMPU_STAGE_POLYGONIZE\t3\nenum\tgmpu_stage\tGMPU_STAGE_EXTRA\t4\n"),
        ("GMPU_ERROR_BUSY\t12\n", "GMPU_ERROR_BUSY\t12\nenum\tgmpu_status\tGMPU_ERROR_NEW\t13\n"),
        (
            "gmpu_surface_set_points_f64\tgmpu_status\tsurface:gmpu_surface *\txyz:const double *",
            "gmpu_surface_set_points_f64\tgmpu_status\tsurface:gmpu_surface *\txyz:const float *",
        ),
        (
            "gmpu_surface_point_count\tsize_t\tsurface:const gmpu_surface *",
            "gmpu_surface_point_count\tsize_t\tsurface:gmpu_surface *",
        ),
        ("fn\tgmpu_abi_version\tuint32_t", "fn\tgmpu_abi_version\tuint64_t"),
        ("fn\tgmpu_abi_version\tuint32_t\n", "fn\tgmpu_abi_version\tuint32_t\nfn\tgmpu_new\tint\n"),
        ("fn\tgmpu_abi_version\tuint32_t\n", ""),
        ("xyz:const double *\tcount:size_t\tstride:size_t", "xyz:const double *\tstride:size_t\tcount:size_t"),
        ("fraction:double", "fraction:float"),
        ("opaque\tgmpu_points\n", "opaque\tgmpu_points\nopaque\tgmpu_octree\n"),
        ("GMPU_ABI_VERSION\t1", "GMPU_ABI_VERSION\t2"),
        ("field\tgmpu_param_info_t\tmin\tdouble", "field\tgmpu_param_info_t\tmin\tfloat"),
        ("field\tgmpu_param_info_t\trefits\tint\n", ""),
    ];
    for (from, to) in edits {
        assert!(text.contains(from), "the summary no longer contains {from:?}: update this test");
        let diffs = differences(&text.replacen(from, to, 1));
        assert!(!diffs.is_empty(), "changing {from:?} to {to:?} went unnoticed");
    }
}
