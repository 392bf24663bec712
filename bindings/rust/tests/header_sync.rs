//! Keeps `gmpu::sys` (and the safe enums) in sync with `include/gmpu/gmpu.h`: the header's
//! function prototypes, the progress-callback typedef, the opaque handles, the enum values
//! and the version defines are parsed and compared with what `sys` declares. Any function,
//! parameter (type or name), return type, enumerator or value that differs fails the test.
//! The header is `../../include/gmpu/gmpu.h`, or `GMPU_HEADER` if set.
use std::collections::BTreeMap;
use std::path::PathBuf;

use gmpu::sys;

fn header_path() -> PathBuf {
    match std::env::var_os("GMPU_HEADER") {
        Some(p) => PathBuf::from(p),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../include/gmpu/gmpu.h"),
    }
}

fn header_text() -> String {
    let path = header_path();
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("cannot read the C header {}: {e}", path.display()))
}

// ---- a small parser for the subset of C the header uses ----------------------------------

#[derive(Debug, Default)]
struct Header {
    functions: BTreeMap<String, (Vec<(String, String)>, String)>, // name → ([(param, rust type)], rust ret)
    enums: BTreeMap<String, Vec<(String, u32)>>,
    opaque: Vec<String>,
    progress_fn: Option<(Vec<String>, String)>,
    defines: BTreeMap<String, u32>,
}

fn strip_comments(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    loop {
        let block = rest.find("/*");
        let line = rest.find("//");
        match (block, line) {
            (Some(b), l) if l.map_or(true, |l| b < l) => {
                out.push_str(&rest[..b]);
                let end = rest[b + 2..].find("*/").expect("unterminated comment in header");
                out.push(' ');
                rest = &rest[b + 2 + end + 2..];
            }
            (_, Some(l)) => {
                out.push_str(&rest[..l]);
                rest = &rest[l..];
                rest = rest.find('\n').map_or("", |n| &rest[n..]);
            }
            _ => {
                out.push_str(rest);
                return out;
            }
        }
    }
}

fn tokens(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut word = String::new();
    for c in text.chars() {
        if c.is_alphanumeric() || c == '_' {
            word.push(c);
        } else {
            if !word.is_empty() {
                out.push(std::mem::take(&mut word));
            }
            if !c.is_whitespace() {
                out.push(c.to_string());
            }
        }
    }
    if !word.is_empty() {
        out.push(word);
    }
    out
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

/// `(name, rust type)` of each parameter in a C parameter list's tokens.
fn params(list: &[String]) -> Vec<(String, String)> {
    if list.is_empty() || (list.len() == 1 && list[0] == "void") {
        return Vec::new();
    }
    list.split(|t| t == ",")
        .map(|p| {
            let (name, ty) = p.split_last().unwrap_or_else(|| panic!("empty parameter in {list:?}"));
            assert!(!ty.is_empty(), "unnamed parameter {p:?}: name every parameter in the header");
            (name.clone(), rust_type(ty))
        })
        .collect()
}

fn parse_header(text: &str) -> Header {
    let text = strip_comments(text);
    let mut h = Header::default();
    let mut code = String::new();
    for line in text.lines() {
        let t = line.trim_start();
        if let Some(rest) = t.strip_prefix("#") {
            let w: Vec<&str> = rest.split_whitespace().collect();
            if w.len() == 3 && w[0] == "define" {
                if let Ok(v) = w[2].parse::<u32>() {
                    h.defines.insert(w[1].to_string(), v);
                }
            }
        } else {
            code.push_str(line);
            code.push('\n');
        }
    }
    let t = tokens(&code);
    let mut i = 0;
    while i < t.len() {
        if t[i] == "GMPU_API" {
            let end = i + t[i..].iter().position(|x| x == ";").expect("prototype without ;");
            let proto = &t[i + 1..end];
            let open = proto.iter().position(|x| x == "(").expect("prototype without (");
            assert_eq!(proto.last().map(String::as_str), Some(")"), "prototype {proto:?}");
            let name = proto[open - 1].clone();
            let ret = rust_type(&proto[..open - 1]);
            let ps = params(&proto[open + 1..proto.len() - 1]);
            assert!(h.functions.insert(name.clone(), (ps, ret)).is_none(), "{name} declared twice");
            i = end;
        } else if t[i] == "typedef" && t.get(i + 1).map(String::as_str) == Some("enum") {
            let open = i + t[i..].iter().position(|x| x == "{").unwrap();
            let close = open + t[open..].iter().position(|x| x == "}").unwrap();
            let name = t[close + 1].clone();
            let mut values = Vec::new();
            let mut next = 0u32;
            for item in t[open + 1..close].split(|x| x == ",").filter(|x| !x.is_empty()) {
                let value = match item {
                    [_] => next,
                    [_, eq, v] if eq == "=" => v.parse().unwrap_or_else(|_| panic!("enum value {item:?}")),
                    _ => panic!("cannot parse enumerator {item:?}"),
                };
                values.push((item[0].clone(), value));
                next = value + 1;
            }
            h.enums.insert(name, values);
            i = close;
        } else if t[i] == "typedef" && t.get(i + 1).map(String::as_str) == Some("struct") {
            h.opaque.push(t[i + 2].clone());
            i += 3;
        } else if t[i] == "typedef" && t.get(i + 1).map(String::as_str) != Some("enum") {
            // typedef RET (*NAME)(PARAMS);
            let end = i + t[i..].iter().position(|x| x == ";").unwrap();
            let td = &t[i + 1..end];
            let star = td.iter().position(|x| x == "*").unwrap_or_else(|| panic!("typedef {td:?}"));
            let name = td[star + 1].clone();
            assert_eq!(name, "gmpu_progress_fn", "new function-pointer typedef {name}: add it to sys");
            let ret = rust_type(&td[..star - 1]);
            let ps = params(&td[star + 4..td.len() - 1]);
            h.progress_fn = Some((ps.into_iter().map(|(_, ty)| ty).collect(), ret));
            i = end;
        }
        i += 1;
    }
    h
}

fn norm(rust_ty: &str) -> String {
    let s: String = rust_ty.chars().filter(|c| !c.is_whitespace()).collect();
    s.replace("std::os::raw::", "").replace("core::ffi::", "").replace("std::ffi::", "")
}

fn screaming(camel: &str) -> String {
    let mut out = String::new();
    for (i, c) in camel.chars().enumerate() {
        if c.is_uppercase() && i > 0 {
            out.push('_');
        }
        out.push(c.to_ascii_uppercase());
    }
    out
}

/// Every difference between the header and the binding, in words.
fn differences(header_text: &str) -> Vec<String> {
    let h = parse_header(header_text);
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
            safe.into_iter().map(|(n, v)| (format!("{prefix}{}", screaming(&n)), v)).collect();
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
    let diffs = differences(&header_text());
    assert!(diffs.is_empty(), "gmpu::sys differs from {}:\n  {}", header_path().display(), diffs.join("\n  "));
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
fn parser_sees_the_whole_header() {
    let h = parse_header(&header_text());
    assert!(h.functions.len() >= 37, "only {} prototypes parsed", h.functions.len());
    assert_eq!(h.enums.len(), 4, "{:?}", h.enums.keys());
    assert_eq!(h.functions["gmpu_surface_set_points_f32"].0[1], ("xyz".into(), "*const f32".into()));
    assert_eq!(h.functions["gmpu_surface_create"].0[0].1, "*mut *mut gmpu_surface");
    assert_eq!(h.functions["gmpu_surface_destroy"].1, "()");
}

/// The comparison must notice drift: each edit of the real header below is a change that
/// sys does not have, and must be reported.
#[test]
fn drift_is_detected() {
    let text = header_text();
    let edits: &[(&str, &str)] = &[
        ("GMPU_PARAM_NOISE_SCALE = 11", "GMPU_PARAM_NOISE_SCALE = 12"),
        ("GMPU_PARAM_NOISE_SCALE = 11", "GMPU_PARAM_NOISE_SCALE = 11,\n    GMPU_PARAM_NEW = 12"),
        ("GMPU_STAGE_POLYGONIZE = 3", "GMPU_STAGE_POLYGONIZE = 3, GMPU_STAGE_EXTRA = 4"),
        ("GMPU_ERROR_INTERNAL = 11", "GMPU_ERROR_INTERNAL = 11, GMPU_ERROR_NEW = 12"),
        (
            "const double *xyz,\n                                                 size_t count",
            "const float *xyz,\n                                                 size_t count",
        ),
        ("gmpu_surface_point_count(const gmpu_surface *surface)", "gmpu_surface_point_count(gmpu_surface *surface)"),
        ("GMPU_API uint32_t gmpu_abi_version(void);", "GMPU_API uint64_t gmpu_abi_version(void);"),
        (
            "GMPU_API uint32_t gmpu_abi_version(void);",
            "GMPU_API uint32_t gmpu_abi_version(void);\nGMPU_API int gmpu_new(void);",
        ),
        ("GMPU_API uint32_t gmpu_abi_version(void);", ""),
        (
            "size_t count, size_t stride);\nGMPU_API gmpu_status gmpu_surface_set_points_f32",
            "size_t stride, size_t count);\nGMPU_API gmpu_status gmpu_surface_set_points_f32",
        ),
        ("(void *user, gmpu_stage stage, double fraction)", "(void *user, gmpu_stage stage, float fraction)"),
        (
            "typedef struct gmpu_points gmpu_points;",
            "typedef struct gmpu_points gmpu_points;\ntypedef struct gmpu_octree gmpu_octree;",
        ),
        ("#define GMPU_ABI_VERSION 1", "#define GMPU_ABI_VERSION 2"),
    ];
    for (from, to) in edits {
        assert!(text.contains(from), "the header no longer contains {from:?}: update this test");
        let diffs = differences(&text.replacen(from, to, 1));
        assert!(!diffs.is_empty(), "changing {from:?} to {to:?} went unnoticed");
    }
}
