//! Every row of the registry is a runnable experiment: its sweeps validate and load their
//! scenes, its script exists, its name is a CLI word, its committed report is there, and every
//! report section of the report crate is some experiment's.

use mirrorbox_experiments::{EXPERIMENTS, Measure, sections};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn every_experiment_is_runnable_and_named_once() {
    for (i, e) in EXPERIMENTS.iter().enumerate() {
        assert!(
            e.name
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'),
            "{}: a CLI word",
            e.name
        );
        assert!(
            !EXPERIMENTS[..i].iter().any(|o| o.name == e.name),
            "{} twice",
            e.name
        );
        assert!(!e.about.is_empty() && !e.about.ends_with('.'), "{}", e.name);
        match &e.measure {
            Measure::Sweeps(configs) => {
                let configs = configs(&e.default_out());
                assert!(!configs.is_empty(), "{}", e.name);
                for mut c in configs {
                    c.validate()
                        .unwrap_or_else(|err| panic!("{}: {err}", e.name));
                    c.scene = root().join(&c.scene);
                    let keys = mirrorbox_harness::point_keys(&c)
                        .unwrap_or_else(|err| panic!("{}: {err}", e.name));
                    assert!(keys.len() > 1, "{}: a floor and points", e.name);
                }
            }
            Measure::Sequences(sequences) => {
                let mut c = sequences(&e.default_out(), "mirrorbox".into(), String::new());
                // Its scenes from the repository root, as `experiment` runs it.
                for s in &mut c.scenarios {
                    s.scene = root().join(&s.scene);
                }
                c.validate()
                    .unwrap_or_else(|err| panic!("{}: {err}", e.name));
            }
            Measure::Script(script, _) => {
                assert!(root().join(script).is_file(), "{}: {script}", e.name);
            }
        }
        if e.main_job {
            assert!(
                root().join(e.default_out()).is_dir(),
                "{}: the main job's experiment has its committed report in {}",
                e.name,
                e.default_out().display()
            );
        }
    }
}

#[test]
fn each_report_section_and_region_is_offered_once() {
    let registered = sections();
    assert!(registered.len() >= 7, "the experiments' own sections");
    for (i, r) in registered.iter().enumerate() {
        assert!(
            !registered[..i].iter().any(|o| std::ptr::fn_addr_eq(*o, *r)),
            "each section offered once"
        );
    }
    let regions = mirrorbox_experiments::regions();
    for (i, r) in regions.iter().enumerate() {
        assert!(
            !regions[..i].iter().any(|o| o.id == r.id),
            "region {:?} declared twice",
            r.id
        );
    }
}

/// The report crate knows documents, charts, statistics and the writer, not the experiments
/// (issue 52): no file of `crates/report/src` is named after an experiment, and none holds an
/// experiment's name or report folder as a string literal (`"table1"`, `"lighting_room"`,
/// `"reports/stereo…"`) — an experiment's section, regions and figures' choices live in its
/// module here.
#[test]
fn the_report_crate_names_no_experiment() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../report/src");
    let mut found = Vec::new();
    for entry in std::fs::read_dir(&src).unwrap().flatten() {
        let file = entry.file_name().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(entry.path()).unwrap();
        for e in EXPERIMENTS {
            let stem = file.trim_end_matches(".rs");
            if stem == e.name.replace('-', "_") || stem == e.folder {
                found.push(format!("src/{file} is named after experiment {}", e.name));
            }
            for word in [e.name, e.folder] {
                for literal in [
                    format!("\"{word}\""),
                    format!("\"{word}/"),
                    format!("\"reports/{word}"),
                ] {
                    if text.contains(&literal) {
                        found.push(format!(
                            "src/{file} holds {literal}… (experiment {})",
                            e.name
                        ));
                    }
                }
            }
        }
    }
    assert!(found.is_empty(), "{}", found.join("\n"));
}

/// An experiment's module without its row (or a row's module without its `pub mod` line)
/// would be silently left out: every `pub const X: Experiment` of `src/*.rs` is in the table.
#[test]
fn every_experiment_module_has_its_row() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    let table = lib
        .split("pub const EXPERIMENTS")
        .nth(1)
        .and_then(|t| t.split("];").next())
        .unwrap();
    let mut consts = 0;
    for entry in std::fs::read_dir(&src).unwrap().flatten() {
        let file = entry.file_name().to_string_lossy().into_owned();
        // A module is a file `NAME.rs` or a folder `NAME/mod.rs` (an experiment with its
        // section and regions beside its row).
        let module = if entry.path().is_dir() {
            file.clone()
        } else {
            match file.strip_suffix(".rs").filter(|m| *m != "lib") {
                Some(m) => m.to_string(),
                None => continue,
            }
        };
        assert!(
            lib.contains(&format!("pub mod {module};")),
            "src/{file} is not a module of the crate: add `pub mod {module};`"
        );
    }
    // Every `Experiment` const of every file, nested ones included (`lighting/x.rs` is
    // module `lighting::x`): each has its row.
    let mut files = vec![src.clone()];
    while let Some(p) = files.pop() {
        if p.is_dir() {
            files.extend(std::fs::read_dir(&p).unwrap().flatten().map(|e| e.path()));
            continue;
        }
        let relative = p.strip_prefix(&src).unwrap().with_extension("");
        let parts: Vec<String> = relative
            .iter()
            .map(|c| c.to_string_lossy().into_owned())
            .filter(|c| c != "mod")
            .collect();
        if parts.is_empty() || parts == ["lib"] || p.extension().is_none_or(|e| e != "rs") {
            continue;
        }
        let module = parts.join("::");
        let text = std::fs::read_to_string(&p).unwrap();
        for line in text
            .lines()
            .filter(|l| l.ends_with(": Experiment = Experiment {"))
        {
            let name = line
                .trim_start_matches("pub const ")
                .split(':')
                .next()
                .unwrap();
            consts += 1;
            assert!(
                table.contains(&format!("&{module}::{name},")),
                "{module}::{name} ({}) is not in EXPERIMENTS",
                p.display()
            );
        }
    }
    assert_eq!(consts, EXPERIMENTS.len(), "one const per row");
}

/// Every registered raster method, and the truth, has a colour and marker no other has in
/// the reports' figures: a method missing from `plot::method_style`'s table gets one from a
/// hash, which may repeat another's (the report crate cannot see the registry; this crate
/// sees both).
#[test]
fn every_registered_method_has_a_style_of_its_own() {
    use mirrorbox_report::plot::method_style;
    let names: Vec<&str> = mirrorbox_raster::METHODS
        .iter()
        .map(|e| e.name)
        .chain(["truth"])
        .collect();
    for (i, a) in names.iter().enumerate() {
        for b in &names[..i] {
            let (sa, sb) = (method_style(a), method_style(b));
            assert!(
                (sa.color, sa.marker) != (sb.color, sb.marker),
                "{a} and {b} share a style: give the new one its own in plot::method_style"
            );
        }
    }
}
