//! The raster crate's modules import one another without cycles (the thin wgpu layer below
//! the methods, the methods below the registry): every `crate::module` reference outside
//! comments and tests is an edge; the graph must be acyclic.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

fn module_graph() -> BTreeMap<String, BTreeSet<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    for dir in [
        src.clone(),
        src.join("methods"),
        src.join("gpu"),
        src.join("plan"),
    ] {
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "rs") {
                files.push(p);
            }
        }
    }
    let mut graph = BTreeMap::new();
    for f in files {
        let rel = f.strip_prefix(&src).unwrap().with_extension("");
        let rel = rel.to_string_lossy();
        // The floors' modules by the names the crate re-exports them under (`targets`,
        // `culling`); their hubs (`gpu`, `plan`) are the items of `device` and `recursion`.
        let name = match rel.as_ref() {
            "lib" | "gpu/mod" | "plan/mod" => continue,
            "gpu/device" => "gpu".to_string(),
            "plan/recursion" => "plan".to_string(),
            r if r.starts_with("gpu/") || r.starts_with("plan/") => {
                r.split('/').nth(1).unwrap().to_string()
            }
            r => r.replace("/mod", "").replace('/', "::"),
        };
        let text = std::fs::read_to_string(&f).unwrap();
        let code = text.split("#[cfg(test)]").next().unwrap();
        let mut deps = BTreeSet::new();
        for line in code.lines() {
            let line = line.split("//").next().unwrap();
            for (i, _) in line.match_indices("crate::") {
                let rest = &line[i + 7..];
                let word: String = rest
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                let mut dep = word.clone();
                if word == "gpu" || word == "plan" {
                    // `crate::gpu::targets::…` names the submodule, `crate::gpu::Gpu` the hub.
                    let sub: String = rest[word.len()..]
                        .trim_start_matches("::")
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect();
                    if src.join(&word).join(format!("{sub}.rs")).is_file() {
                        dep = sub;
                    }
                }
                if word == "methods" {
                    let sub: String = rest[word.len()..]
                        .trim_start_matches("::")
                        .chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                        .collect();
                    if src.join("methods").join(format!("{sub}.rs")).is_file() {
                        dep = format!("methods::{sub}");
                    }
                }
                // `crate::host_layout!` and `crate::mirror_plane_shaders!` are macros; an item
                // re-exported at the root (`crate::Clipping`) is no module of its own.
                let module = dep.starts_with(char::is_lowercase)
                    && dep != "host_layout"
                    && dep != "mirror_plane_shaders";
                if dep != name && module {
                    deps.insert(dep);
                }
            }
            if name == "methods"
                && let Some(m) = line.trim().strip_prefix("pub mod ")
            {
                deps.insert(format!("methods::{}", m.trim_end_matches(';')));
            }
        }
        graph.insert(name, deps);
    }
    graph
}

#[test]
fn module_imports_have_no_cycle() {
    let graph = module_graph();
    assert!(graph.len() >= 15, "{graph:?}");
    assert!(graph["methods"].contains("methods::unrolled"));
    // Depth-first search for a back edge.
    fn visit(
        n: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) {
        match state.get(n) {
            Some(2) => return,
            Some(1) => panic!("import cycle: {} -> {n}", path.join(" -> ")),
            _ => {}
        }
        state.insert(n.to_string(), 1);
        path.push(n.to_string());
        for d in graph.get(n).into_iter().flatten() {
            if graph.contains_key(d) {
                visit(d, graph, state, path);
            }
        }
        path.pop();
        state.insert(n.to_string(), 2);
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        visit(n, &graph, &mut state, &mut Vec::new());
    }
}

/// Every `MethodEntry` declared in a file of `src/methods/` has its row in `METHODS`: a
/// method whose row was forgotten would compile and silently be missing everywhere.
#[test]
fn every_declared_method_has_its_row_in_the_table() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/methods");
    let mut declared = Vec::new();
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        let text = std::fs::read_to_string(&p).unwrap();
        let mut rest = text.as_str();
        while let Some(i) = rest.find(": MethodEntry = MethodEntry {") {
            rest = &rest[i..];
            let name = rest
                .split("name: \"")
                .nth(1)
                .and_then(|s| s.split('"').next())
                .unwrap_or_else(|| panic!("{}: an entry without a name", p.display()));
            declared.push(name.to_string());
            rest = &rest[1..];
        }
    }
    assert!(declared.len() >= 4, "{declared:?}");
    for name in &declared {
        assert!(
            mirrorbox_raster::registry::find(name).is_some(),
            "method {name} is declared but has no row in METHODS (src/methods/mod.rs)"
        );
    }
    assert_eq!(declared.len(), mirrorbox_raster::METHODS.len());
}

/// A method's documentation is part of adding it (CONTRIBUTING, step 5): every registered
/// method has a heading of its own in `docs/methods.md` (its name in backticks), and every
/// WGSL file under `shaders/` its row in `shaders/README.md`.
#[test]
fn every_method_and_shader_is_documented() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let methods = std::fs::read_to_string(root.join("docs/methods.md")).unwrap();
    let headings: Vec<&str> = methods.lines().filter(|l| l.starts_with('#')).collect();
    for e in mirrorbox_raster::METHODS {
        let name = format!("`{}`", e.name);
        assert!(
            headings.iter().any(|h| h.contains(&name)),
            "docs/methods.md has no heading naming {name}: add its paragraph (CONTRIBUTING, step 5)"
        );
    }
    let readme = std::fs::read_to_string(root.join("shaders/README.md")).unwrap();
    for entry in std::fs::read_dir(root.join("shaders")).unwrap().flatten() {
        let file = entry.file_name().to_string_lossy().into_owned();
        if file.ends_with(".wgsl") {
            assert!(
                readme.contains(&format!("| `{file}` |")),
                "shaders/README.md has no row for {file} (CONTRIBUTING, step 5)"
            );
        }
    }
}

/// No function of a method is longer than [`MAX_METHOD_FN_LINES`] (issue 52): a method's
/// constructor reads as its phases (its records, its bind groups through
/// `pipeline::BindGroupBuilder`, its pipelines, its stats), each a named function, as kajiya's
/// passes read through their builder. Counted on the rustfmt'd source, from a `fn` line to
/// the closing brace at its indentation.
#[test]
fn no_method_function_is_longer_than_its_phases() {
    const MAX_METHOD_FN_LINES: usize = 120;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/methods");
    let mut long = Vec::new();
    for e in std::fs::read_dir(&dir).unwrap() {
        let path = e.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let mut i = 0;
        while i < lines.len() {
            let line = lines[i];
            let indent = line.len() - line.trim_start().len();
            let head = line.trim_start();
            let is_fn = ["fn ", "pub fn ", "pub(crate) fn "]
                .iter()
                .any(|p| head.starts_with(p))
                && !line.trim_end().ends_with(';');
            if is_fn {
                let close = format!("{}}}", " ".repeat(indent));
                let end = (i..lines.len()).find(|&j| lines[j] == close).unwrap_or(i);
                let n = end - i + 1;
                if n > MAX_METHOD_FN_LINES {
                    long.push(format!(
                        "{}:{} `{}` is {n} lines",
                        path.file_name().unwrap().to_string_lossy(),
                        i + 1,
                        head.split('(').next().unwrap()
                    ));
                }
                i = end;
            }
            i += 1;
        }
    }
    assert!(
        long.is_empty(),
        "longer than {MAX_METHOD_FN_LINES} lines: split into named phases\n{}",
        long.join("\n")
    );
}
