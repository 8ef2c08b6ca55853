//! The crates' modules import each other in one direction only: no module cycle, read from the
//! sources. An edge runs from a module to every module of its crate it names (in `use` lines,
//! braces expanded, and in `crate::` paths); a module's edges into its own ancestors or
//! descendants do not count (a parent lists its children). Test modules are left out.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

type Module = Vec<String>;

fn sources(dir: &Path, root: &Path, out: &mut BTreeMap<Module, String>) {
    for entry in std::fs::read_dir(dir).expect("a source folder") {
        let path = entry.expect("an entry").path();
        if path.is_dir() {
            sources(&path, root, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            let rel = path.strip_prefix(root).unwrap().with_extension("");
            let mut m: Module = rel
                .iter()
                .map(|c| c.to_string_lossy().into_owned())
                .collect();
            if matches!(m.last().map(String::as_str), Some("mod" | "lib" | "main")) {
                m.pop();
            }
            let text = std::fs::read_to_string(&path).unwrap();
            // The unit tests at the end of a file may reach anywhere.
            let code = match text.find("#[cfg(test)]\nmod tests") {
                Some(i) => text[..i].to_string(),
                None => text,
            };
            out.insert(m, code);
        }
    }
}

/// The paths of one `use` tree, braces expanded.
fn expand(prefix: &[String], tree: &str, out: &mut Vec<Vec<String>>) {
    let tree = tree.trim();
    if let Some(open) = tree.find('{') {
        let head: Vec<String> = tree[..open]
            .split("::")
            .filter(|s| !s.trim().is_empty())
            .map(|s| s.trim().to_string())
            .collect();
        let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
        let mut prefix = prefix.to_vec();
        prefix.extend(head);
        let (mut depth, mut start) = (0, 0);
        for (i, c) in inner.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    expand(&prefix, &inner[start..i], out);
                    start = i + 1;
                }
                _ => {}
            }
        }
        expand(&prefix, &inner[start..], out);
    } else if !tree.is_empty() {
        let mut p = prefix.to_vec();
        let name = tree.split(" as ").next().unwrap_or(tree);
        p.extend(name.split("::").map(|s| s.trim().to_string()));
        out.push(p);
    }
}

/// The module of the crate a path names, from module `m`.
fn resolve(m: &Module, path: &[String], modules: &BTreeSet<Module>) -> Option<Module> {
    let mut p: Module = match path.first().map(String::as_str) {
        Some("crate") => path[1..].to_vec(),
        Some("super") => {
            let mut base = m.clone();
            let mut rest = path;
            while rest.first().is_some_and(|s| s == "super") {
                base.pop();
                rest = &rest[1..];
            }
            base.extend(rest.iter().cloned());
            base
        }
        Some("self") => {
            let mut base = m.clone();
            base.extend(path[1..].iter().cloned());
            base
        }
        _ => return None,
    };
    while !p.is_empty() && !modules.contains(&p) {
        p.pop();
    }
    (!p.is_empty()).then_some(p)
}

fn cycles(src: &Path) -> Vec<Vec<Module>> {
    let mut files = BTreeMap::new();
    sources(src, src, &mut files);
    let modules: BTreeSet<Module> = files.keys().cloned().collect();
    let mut edges: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for (m, code) in &files {
        let mut paths = Vec::new();
        for (i, _) in code.match_indices("use ") {
            // A `use` item: only visibility before it on its line.
            let line_start = code[..i].rfind('\n').map_or(0, |n| n + 1);
            let before = code[line_start..i].trim();
            let tree = &code[i + 4..];
            let tree = &tree[..tree.find(';').unwrap_or(tree.len())];
            let local = ["crate", "super", "self"]
                .iter()
                .any(|k| tree.starts_with(k));
            if local && (before.is_empty() || before.starts_with("pub")) {
                expand(&[], tree, &mut paths);
            }
        }
        for (i, _) in code.match_indices("crate::") {
            let path: Vec<String> = code[i..]
                .split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .next()
                .unwrap_or("")
                .split("::")
                .filter(|s| !s.is_empty())
                .map(str::to_string)
                .collect();
            paths.push(path);
        }
        for p in paths {
            if let Some(t) = resolve(m, &p, &modules) {
                let related = t.starts_with(m) || m.starts_with(&t);
                if !related {
                    edges.entry(m.clone()).or_default().insert(t);
                }
            }
        }
    }
    // Tarjan's strongly connected components.
    struct State<'a> {
        edges: &'a BTreeMap<Module, BTreeSet<Module>>,
        index: BTreeMap<Module, usize>,
        low: BTreeMap<Module, usize>,
        stack: Vec<Module>,
        out: Vec<Vec<Module>>,
    }
    fn visit(s: &mut State, v: &Module) {
        let n = s.index.len();
        s.index.insert(v.clone(), n);
        s.low.insert(v.clone(), n);
        s.stack.push(v.clone());
        for w in s.edges.get(v).into_iter().flatten() {
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if s.stack.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = s.stack.pop() {
                let done = &w == v;
                comp.push(w);
                if done {
                    break;
                }
            }
            if comp.len() > 1 {
                s.out.push(comp);
            }
        }
    }
    let mut s = State {
        edges: &edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        out: Vec::new(),
    };
    for m in &modules {
        if !s.index.contains_key(m) {
            visit(&mut s, m);
        }
    }
    s.out
}

#[test]
fn no_crate_has_a_module_cycle() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    for name in ["voxgi", "voxgi-scene", "voxgi-viewer", "voxgi-cli"] {
        let src: PathBuf = crates.join(name).join("src");
        let found = cycles(&src);
        assert!(
            found.is_empty(),
            "{name}: modules that import each other: {:?}",
            found
                .iter()
                .map(|c| c.iter().map(|m| m.join("::")).collect::<Vec<_>>())
                .collect::<Vec<_>>()
        );
    }
}

/// The checker finds a cycle where there is one (so the test above can fail).
#[test]
fn the_cycle_check_sees_a_cycle() {
    let dir = std::env::temp_dir().join(format!("voxgi_layering_{}", std::process::id()));
    std::fs::create_dir_all(dir.join("b")).unwrap();
    std::fs::write(dir.join("lib.rs"), "mod a;\nmod b;\n").unwrap();
    std::fs::write(dir.join("a.rs"), "use crate::b::{Thing, other::More};\n").unwrap();
    std::fs::write(dir.join("b/mod.rs"), "pub mod other;\nuse super::a;\n").unwrap();
    std::fs::write(dir.join("b/other.rs"), "pub struct More;\n").unwrap();
    let found = cycles(&dir);
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].len(), 2, "{found:?}");
}
