//! The test build's profile (`Cargo.toml`, `[profile.dev]`): the code that runs only inside
//! the compiler — every procedural macro the build compiles on this platform, and the
//! parser crates they are made of (`syn`, `quote`, `proc-macro2`) — is compiled unoptimised.
//!
//! Why a test: `[profile.dev.package."*"]` (opt-level 2 for the dependencies the tests run)
//! also applies to proc macros — a named package's or `"*"`'s settings win over
//! `build-override` — and optimised they took 108 s of a test build's compiler time from
//! scratch on two cores, 12 s unoptimised (55 s less in all, their expansion a little slower;
//! docs/budgets.md). A dependency update that brings a new proc macro would silently be
//! optimised again; this names it.

use crate::common::repo;
use std::collections::BTreeSet;

/// The crates that run only inside the compiler besides the proc macros themselves.
const MACRO_PARSERS: [&str; 3] = ["syn", "quote", "proc-macro2"];

/// The packages `Cargo.toml` names `[profile.dev.package.NAME]` with `opt-level = 0`.
fn unoptimised_in_dev(manifest: &str) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    let mut current: Option<String> = None;
    for line in manifest.lines().map(str::trim) {
        if line.starts_with('[') {
            current = line
                .strip_prefix("[profile.dev.package.")
                .and_then(|rest| rest.strip_suffix(']'))
                .map(|name| name.trim_matches('"').to_string());
        } else if let Some(name) = &current
            && line.replace(' ', "") == "opt-level=0"
        {
            names.insert(name.clone());
        }
    }
    names
}

/// This host's target triple (`rustc -vV`).
fn host() -> String {
    let out = std::process::Command::new("rustc")
        .arg("-vV")
        .output()
        .expect("rustc runs");
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    text.lines()
        .find_map(|l| l.strip_prefix("host: "))
        .unwrap_or_else(|| panic!("no `host:` line in `rustc -vV`:\n{text}"))
        .to_string()
}

/// The proc-macro packages of the workspace's dependency graph on this host.
fn proc_macros_built_here() -> BTreeSet<String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .current_dir(repo())
        .args(["metadata", "--format-version", "1", "--locked", "--offline"])
        .args(["--filter-platform", &host()])
        .output()
        .expect("cargo metadata runs");
    assert!(
        out.status.success(),
        "cargo metadata failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let meta: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("cargo metadata's JSON");
    // Only the packages the resolve reaches on this host (`packages` lists every locked one).
    let reached: BTreeSet<&str> = meta["resolve"]["nodes"]
        .as_array()
        .expect("resolve.nodes")
        .iter()
        .filter_map(|n| n["id"].as_str())
        .collect();
    meta["packages"]
        .as_array()
        .expect("packages")
        .iter()
        .filter(|p| p["id"].as_str().is_some_and(|id| reached.contains(id)))
        .filter(|p| {
            p["targets"].as_array().into_iter().flatten().any(|t| {
                t["kind"]
                    .as_array()
                    .into_iter()
                    .flatten()
                    .any(|k| k == "proc-macro")
            })
        })
        .filter_map(|p| p["name"].as_str().map(str::to_string))
        .collect()
}

#[test]
fn every_proc_macro_is_compiled_unoptimised_in_the_test_build() {
    let manifest = std::fs::read_to_string(repo().join("Cargo.toml")).expect("Cargo.toml");
    let unoptimised = unoptimised_in_dev(&manifest);
    let macros = proc_macros_built_here();
    assert!(
        macros.contains("serde_derive"),
        "the graph has serde_derive; found only {macros:?}"
    );
    let missing: Vec<&str> = macros
        .iter()
        .map(String::as_str)
        .chain(MACRO_PARSERS)
        .filter(|name| !unoptimised.contains(*name))
        .collect();
    assert!(
        missing.is_empty(),
        "Cargo.toml: add `[profile.dev.package.NAME]` with `opt-level = 0` for {missing:?}: \
         code that runs only inside the compiler, which `[profile.dev.package.\"*\"]` would \
         otherwise optimise at the test build's cost (docs/budgets.md)"
    );
}

#[test]
fn the_profile_reader_finds_named_packages_at_opt_level_zero() {
    let manifest = "[profile.dev.package.\"*\"]\nopt-level = 2\n[profile.dev.package.syn]\n\
                    opt-level = 0\n[profile.dev.package.quote]\nopt-level = 1\n\
                    [profile.release]\nopt-level = 0\n";
    assert_eq!(
        unoptimised_in_dev(manifest),
        BTreeSet::from(["syn".to_string()])
    );
}
