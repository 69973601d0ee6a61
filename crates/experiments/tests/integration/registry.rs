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
                sequences(&e.default_out(), "mirrorbox".into(), String::new())
                    .validate()
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
fn every_report_section_belongs_to_an_experiment() {
    use mirrorbox_report::sections as s;
    let known: [mirrorbox_report::Section; 6] = [
        s::table1,
        s::depth_scaling,
        s::symmetry_scaling,
        s::lighting,
        s::uneven_mirrors,
        s::stereo,
    ];
    let registered = sections();
    for k in known {
        assert!(
            registered.iter().any(|r| std::ptr::fn_addr_eq(*r, k)),
            "a section of the report crate no experiment offers"
        );
    }
    for (i, r) in registered.iter().enumerate() {
        assert!(
            !registered[..i].iter().any(|o| std::ptr::fn_addr_eq(*o, *r)),
            "each section offered once"
        );
    }
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
        let Some(module) = file.strip_suffix(".rs").filter(|m| *m != "lib") else {
            continue;
        };
        assert!(
            lib.contains(&format!("pub mod {module};")),
            "src/{file} is not a module of the crate: add `pub mod {module};`"
        );
        let text = std::fs::read_to_string(entry.path()).unwrap();
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
                "{module}::{name} is not in EXPERIMENTS"
            );
        }
    }
    assert_eq!(consts, EXPERIMENTS.len(), "one const per row");
}
