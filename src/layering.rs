//! The crate's dependencies run one way, and no module imports itself back
//! through others: a test over the source (`cargo test`).
//!
//! Every `crate::`, `super::` and `self::` path in a file (use lines and
//! paths in code, outside `#[cfg(test)]` modules and the test-only files)
//! is resolved to the file that defines what it names, following `pub use`
//! re-exports: `crate::eye::GBuffer` is a dependency on `eye/gbuffer.rs`,
//! not on `eye/mod.rs`. Two checks on that graph of files:
//!
//! * **Layers.** bindings (`python`) -> API (`api`: the use cases and the
//!   backend choice) -> planner (`auto`) -> orchestrators (`pipeline`: one
//!   per view) -> stages (`eye`, `light_view`, `frame`, and their GPU
//!   twins `gpu`) ->
//!   methods and raster -> the ray engine (`trace`) -> geometry (`geom`) -> leaves (`error`, `memory`,
//!   `threads`, `timing`, `backend`, `block_cache`). A file may import its
//!   own layer or lower ones, never a higher one (so `gpu/` never imports
//!   an orchestrator).
//! * **No circle**: no file reaches itself, in a layer or across.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layer of a module path (its first segment); higher runs first.
fn layer(module: &[String]) -> usize {
    match module.first().map(String::as_str) {
        Some("python") => 9,
        Some("api") => 8,
        Some("auto") => 7,
        Some("pipeline") => 6,
        Some("eye" | "frame" | "light_view" | "gpu") => 5,
        Some("methods" | "raster") => 4,
        Some("trace") => 3,
        Some("geom") => 2,
        Some(
            "error" | "error_estimate" | "memory" | "threads" | "timing" | "backend"
            | "block_cache" | "cancel",
        ) => 1,
        other => panic!("src/layering.rs: no layer for module {other:?}; add it to `layer`"),
    }
}

/// Files that only hold tests.
fn test_only(module: &[String]) -> bool {
    matches!(
        module.last().map(String::as_str),
        Some("tests" | "device_tests" | "shader_tests" | "layering")
    )
}

type Module = Vec<String>;

fn modules(src: &Path) -> BTreeMap<Module, PathBuf> {
    fn walk(dir: &Path, src: &Path, out: &mut BTreeMap<Module, PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                walk(&p, src, out);
            } else if p.extension().is_some_and(|e| e == "rs") {
                let rel = p.strip_prefix(src).unwrap().with_extension("");
                let mut m: Module = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                if m.last().is_some_and(|l| l == "mod") {
                    m.pop();
                }
                if m == ["lib"] {
                    m.clear();
                }
                out.insert(m, p);
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(src, src, &mut out);
    out
}

/// The source without string and char literals (emptied), comments, and
/// `#[cfg(test)]` items (a module or a function: the brace block that
/// follows the attribute).
fn code(text: &str) -> String {
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut k = 0;
    while k < c.len() {
        match c[k] {
            '/' if c.get(k + 1) == Some(&'/') => {
                while k < c.len() && c[k] != '\n' {
                    k += 1;
                }
            }
            '/' if c.get(k + 1) == Some(&'*') => {
                k += 2;
                while k + 1 < c.len() && !(c[k] == '*' && c[k + 1] == '/') {
                    k += 1;
                }
                k += 2;
            }
            'r' if (c.get(k + 1) == Some(&'"') || c.get(k + 1) == Some(&'#'))
                && !c[..k]
                    .last()
                    .is_some_and(|p| p.is_alphanumeric() || *p == '_') =>
            {
                // A raw string: r"..." or r#"..."#.
                let mut j = k + 1;
                let mut hashes = 0;
                while c.get(j) == Some(&'#') {
                    hashes += 1;
                    j += 1;
                }
                if c.get(j) != Some(&'"') {
                    out.push(c[k]);
                    k += 1;
                    continue;
                }
                j += 1;
                while j < c.len()
                    && !(c[j] == '"'
                        && c[j + 1..]
                            .iter()
                            .take(hashes)
                            .filter(|h| **h == '#')
                            .count()
                            == hashes)
                {
                    j += 1;
                }
                out.push_str("\"\"");
                k = j + 1 + hashes;
            }
            '"' => {
                k += 1;
                while k < c.len() && c[k] != '"' {
                    k += if c[k] == '\\' { 2 } else { 1 };
                }
                out.push_str("\"\"");
                k += 1;
            }
            '\'' if c.get(k + 2) == Some(&'\'') || c.get(k + 1) == Some(&'\\') => {
                // A char literal ('x' or '\n'); a lifetime has no closing quote.
                k += 1;
                while k < c.len() && c[k] != '\'' {
                    k += if c[k] == '\\' { 2 } else { 1 };
                }
                out.push_str("' '");
                k += 1;
            }
            ch => {
                out.push(ch);
                k += 1;
            }
        }
    }
    let mut s = out;
    while let Some(i) = s.find("#[cfg(test)]") {
        let Some(open) = s[i..].find('{').map(|o| i + o) else {
            break;
        };
        // A `mod x;` declaration ends at its semicolon before any brace.
        if let Some(semi) = s[i..open].find(';') {
            s.replace_range(i..i + semi + 1, "");
            continue;
        }
        let mut depth = 0;
        let mut end = open;
        for (k, ch) in s[open..].char_indices() {
            match ch {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        end = open + k + 1;
                        break;
                    }
                }
                _ => {}
            }
        }
        s.replace_range(i..end, "");
    }
    // An inline module (`mod avx2 { use super::X; }`) is part of its
    // file: its `super::` is the file's `self::`.
    let mut from = 0;
    while let Some(i) = s[from..].find("mod ").map(|i| from + i) {
        let decl = &s[i + 4..];
        let ident = decl
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .unwrap_or(decl.len());
        let after = decl[ident..].trim_start();
        let at_item = s[..i]
            .chars()
            .last()
            .is_none_or(|c| c.is_whitespace() || c == ';' || c == '}' || c == '{');
        if ident > 0 && at_item && after.starts_with('{') {
            let open = i + 4 + ident + (decl[ident..].len() - after.len());
            let mut depth = 0;
            let mut end = s.len();
            for (k, ch) in s[open..].char_indices() {
                match ch {
                    '{' => depth += 1,
                    '}' => {
                        depth -= 1;
                        if depth == 0 {
                            end = open + k;
                            break;
                        }
                    }
                    _ => {}
                }
            }
            let body = s[open..end].replace("super::", "self::");
            s.replace_range(open..end, &body);
            from = open + body.len();
        } else {
            from = i + 4;
        }
    }
    s
}

/// The paths of `use` items, brace groups expanded: `a::{b, c::{d}}` ->
/// `a::b`, `a::c::d`. Each with whether the item re-exports (`pub use`).
fn use_paths(code: &str) -> Vec<(String, bool)> {
    fn expand(prefix: &str, tree: &str, out: &mut Vec<String>) {
        let tree = tree.trim();
        if let Some(open) = tree.find('{') {
            let head = format!("{prefix}{}", &tree[..open]);
            let inner = &tree[open + 1..tree.rfind('}').unwrap()];
            let (mut depth, mut start) = (0, 0);
            for (k, ch) in inner.char_indices() {
                match ch {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        expand(&head, &inner[start..k], out);
                        start = k + 1;
                    }
                    _ => {}
                }
            }
            expand(&head, &inner[start..], out);
        } else if !tree.is_empty() {
            let path = tree.split(" as ").next().unwrap().trim();
            out.push(format!("{prefix}{path}"));
        }
    }
    let mut out = vec![];
    let mut rest = code;
    while let Some(i) = rest.find("use ") {
        let before = &rest[..i];
        let at_item_start = before
            .chars()
            .last()
            .is_none_or(|c| c.is_whitespace() || c == ';' || c == '{' || c == ')');
        let end = rest[i..].find(';').map(|e| i + e);
        let Some(end) = end else { break };
        if at_item_start {
            let line_start = before.rfind(['\n', ';', '{', '}']).map_or(0, |k| k + 1);
            let public = before[line_start..].trim_start().starts_with("pub");
            let mut paths = vec![];
            expand("", &rest[i + 4..end], &mut paths);
            out.extend(paths.into_iter().map(|p| (p.replace(' ', ""), public)));
        }
        rest = &rest[end + 1..];
    }
    out
}

/// Paths named in code outside `use` items: `crate::a::b`, `super::x`.
fn code_paths(code: &str) -> Vec<String> {
    let mut out = vec![];
    for root in ["crate::", "super::"] {
        let mut rest = code;
        while let Some(i) = rest.find(root) {
            let prev = rest[..i].chars().last();
            let tail = &rest[i..];
            let len = tail
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(tail.len());
            // A prefix of a brace group (`super::{a, b}`) names nothing
            // itself: its items are `use_paths`'.
            let group = tail[len..].starts_with('{');
            // `pub(in crate::x)` is a visibility, not a dependency.
            let visibility = rest[..i].ends_with("in ");
            if !group
                && !visibility
                && !prev.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':')
            {
                out.push(tail[..len].trim_end_matches(':').to_string());
            }
            rest = &rest[i + len.max(1)..];
        }
    }
    out
}

/// `path` as seen from `module` (file `is_mod`: a `mod.rs` or `lib.rs`)
/// in absolute segments, or `None` for an external crate.
fn absolute(
    module: &[String],
    is_mod: bool,
    path: &str,
    children: &BTreeSet<String>,
) -> Option<Module> {
    let segs: Vec<&str> = path.split("::").filter(|s| !s.is_empty()).collect();
    let (&first, rest) = segs.split_first()?;
    // The module a `self::`/`super::` path starts from: a mod.rs is its
    // own directory's module, another file its parent's child.
    let here: Module = module.to_vec();
    let mut base = match first {
        "crate" => vec![],
        "self" => here.clone(),
        "super" => {
            let mut b = here.clone();
            b.pop();
            b
        }
        child if is_mod && children.contains(child) => {
            let mut b = here.clone();
            b.push(child.to_string());
            return Some(
                b.into_iter()
                    .chain(rest.iter().map(|s| s.to_string()))
                    .collect(),
            );
        }
        _ => return None,
    };
    let mut rest = rest;
    while let Some((&"super", r)) = rest.split_first() {
        base.pop();
        rest = r;
    }
    base.extend(rest.iter().filter(|s| **s != "self").map(|s| s.to_string()));
    Some(base)
}

struct Crate {
    files: BTreeMap<Module, PathBuf>,
    /// (module, name) -> the absolute path a `pub use` there names.
    reexports: BTreeMap<(Module, String), Module>,
    /// Per file: the absolute paths it names.
    paths: BTreeMap<Module, Vec<Module>>,
}

impl Crate {
    fn read(src: &Path) -> Crate {
        let files = modules(src);
        let mut reexports = BTreeMap::new();
        let mut paths = BTreeMap::new();
        for (m, p) in &files {
            let text = code(&std::fs::read_to_string(p).unwrap());
            let is_mod = p.ends_with("mod.rs") || p.ends_with("lib.rs");
            let children: BTreeSet<String> = files
                .keys()
                .filter(|k| k.len() == m.len() + 1 && k.starts_with(m))
                .map(|k| k.last().unwrap().clone())
                .collect();
            let mut named = vec![];
            for (path, public) in use_paths(&text) {
                let Some(abs) = absolute(m, is_mod, &path, &children) else {
                    continue;
                };
                if public {
                    let name = path.rsplit("::").next().unwrap().to_string();
                    if name != "*" && name != "self" {
                        reexports.insert((m.clone(), name), abs.clone());
                    }
                }
                named.push(abs);
            }
            for path in code_paths(&text) {
                if let Some(abs) = absolute(m, is_mod, &path, &children) {
                    named.push(abs);
                }
            }
            paths.insert(m.clone(), named);
        }
        Crate {
            files,
            reexports,
            paths,
        }
    }

    /// The file that defines what `path` names: the longest prefix that is
    /// a file, then through that file's re-export of the next segment.
    fn defining_file(&self, path: &[String], depth: usize) -> Option<Module> {
        let n = (0..=path.len())
            .rev()
            .find(|&n| self.files.contains_key(&path[..n]))?;
        let file = path[..n].to_vec();
        if depth < 16 {
            if let Some(next) = path.get(n) {
                if let Some(target) = self.reexports.get(&(file.clone(), next.clone())) {
                    let mut t = target.clone();
                    t.extend(path[n + 1..].iter().cloned());
                    return self.defining_file(&t, depth + 1).or(Some(file));
                }
            }
        }
        Some(file)
    }

    fn graph(&self) -> BTreeMap<Module, BTreeSet<Module>> {
        let mut g = BTreeMap::new();
        for (m, named) in &self.paths {
            if test_only(m) || m.is_empty() {
                continue;
            }
            let deps: BTreeSet<Module> = named
                .iter()
                .filter_map(|p| self.defining_file(p, 0))
                .filter(|d| d != m && !d.is_empty() && !test_only(d))
                .collect();
            g.insert(m.clone(), deps);
        }
        g
    }
}

fn name(m: &[String]) -> String {
    m.join("/")
}

fn graph() -> BTreeMap<Module, BTreeSet<Module>> {
    Crate::read(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src")).graph()
}

#[test]
fn every_dependency_points_to_the_same_layer_or_a_lower_one() {
    let mut upward = vec![];
    for (m, deps) in graph() {
        for d in deps {
            if layer(&d) > layer(&m) {
                upward.push(format!("{} -> {}", name(&m), name(&d)));
            }
        }
    }
    assert!(upward.is_empty(), "imports that go up a layer: {upward:#?}");
}

/// Files that reach each other: the strongly connected components of more
/// than one file, each sorted, the list sorted.
fn circles(g: &BTreeMap<Module, BTreeSet<Module>>) -> Vec<Vec<String>> {
    let reach = |from: &Module| {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.clone()];
        while let Some(m) = stack.pop() {
            for d in g.get(&m).into_iter().flatten() {
                if seen.insert(d.clone()) {
                    stack.push(d.clone());
                }
            }
        }
        seen
    };
    let reached: BTreeMap<&Module, BTreeSet<Module>> = g.keys().map(|m| (m, reach(m))).collect();
    let mut out: BTreeSet<Vec<String>> = BTreeSet::new();
    for (m, r) in &reached {
        if !r.contains(*m) {
            continue;
        }
        let comp: Vec<String> = r
            .iter()
            .filter(|d| reached.get(d).is_some_and(|back| back.contains(*m)))
            .map(|d| name(d))
            .collect();
        out.insert(comp);
    }
    out.into_iter().collect()
}

#[test]
fn no_module_reaches_itself() {
    let found = circles(&graph());
    assert!(
        found.is_empty(),
        "import circles (files that reach each other): {found:#?}"
    );
}

/// The variants of the kernel enum (`Method::Exact`, ...) a file's code
/// (tests left out) names.
fn method_variants(code: &str) -> Vec<String> {
    let b = code.as_bytes();
    let mut out = vec![];
    for (k, _) in code.match_indices("Method::") {
        let word_start = k == 0 || !(b[k - 1].is_ascii_alphanumeric() || b[k - 1] == b'_');
        let rest = &code[k + "Method::".len()..];
        if word_start && rest.starts_with(|c: char| c.is_ascii_uppercase()) {
            let end = rest
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .unwrap_or(rest.len());
            out.push(rest[..end].to_string());
        }
    }
    out
}

/// No stage, orchestrator, planner, API or binding tells the methods apart
/// by their kernel's variant: each asks the kernel (`methods::Kernel`,
/// `ShadowMethod`), so a new method is its module, its registry line and
/// its GPU kernel (`gpu/`, whose `gpu::kernel` is the one place there that
/// picks one). Checked on the code outside tests.
#[test]
fn no_stage_names_a_method() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut named = vec![];
    for (m, p) in modules(&src) {
        if m.is_empty() || test_only(&m) || matches!(m[0].as_str(), "methods" | "gpu") {
            continue;
        }
        let found = method_variants(&code(&std::fs::read_to_string(&p).unwrap()));
        if !found.is_empty() {
            named.push((name(&m), found));
        }
    }
    assert!(
        named.is_empty(),
        "files naming a method's kernel: {named:?}"
    );
    assert_eq!(
        method_variants("let a = Method::Exact(k); ShadowMethod::f(); Method::kernel;"),
        ["Exact"]
    );
}

/// The checks find what they look for: a circle and an upward import in a
/// small made-up crate, and the re-export rule.
#[test]
fn the_checks_see_circles_upward_imports_and_reexports() {
    let dir = std::env::temp_dir().join(format!("softshadow-layering-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("eye")).unwrap();
    std::fs::create_dir_all(dir.join("methods")).unwrap();
    let write = |p: &str, t: &str| std::fs::write(dir.join(p), t).unwrap();
    write("lib.rs", "pub mod eye;\npub mod methods;\npub mod api;\n");
    write("api.rs", "use crate::eye::Image;\n");
    write(
        "eye/mod.rs",
        "mod image;\nmod stage;\npub use image::Image;\n",
    );
    write(
        "eye/image.rs",
        "use super::stage::run;\npub struct Image;\n",
    );
    write("eye/stage.rs", "use crate::eye::Image;\npub fn run() {}\n");
    write(
        "methods/mod.rs",
        "#[cfg(test)]\nmod tests {\n use crate::api::x;\n}\nfn f() { crate::api::y(); }\n",
    );
    let g = Crate::read(&dir).graph();
    let _ = std::fs::remove_dir_all(&dir);
    let m = |s: &str| s.split('/').map(String::from).collect::<Module>();
    // Through the re-export: api depends on eye/image, not eye/mod.rs.
    assert_eq!(g[&m("api")], BTreeSet::from([m("eye/image")]));
    // eye/image <-> eye/stage is a circle.
    assert_eq!(
        circles(&g),
        vec![vec!["eye/image".to_string(), "eye/stage".to_string()]]
    );
    // Code paths count; the test module does not.
    assert_eq!(g[&m("methods")], BTreeSet::from([m("api")]));
    assert!(layer(&m("api")) > layer(&m("methods")));
}
