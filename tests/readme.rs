//! The README's and the docs' numbers are the committed reports' numbers: every generated
//! region of `README.md` and `docs/methods.md` must be what `mirrorbox readme` makes from
//! `reports/` (issue #13).

use crate::common::{mirrorbox, repo};

#[test]
fn the_readme_agrees_with_the_committed_reports() {
    let out = mirrorbox(&["readme", "--check"], &[]);
    assert_eq!(
        out.code, 0,
        "{}{}\n(after changing a report, run `mirrorbox readme` and commit README.md)",
        out.stdout, out.stderr
    );
    // Every region the generator knows is used, so no report figure is quoted by hand.
    let text: String = ["README.md", "docs/methods.md"]
        .iter()
        .map(|f| std::fs::read_to_string(repo().join(f)).unwrap())
        .collect();
    for (id, _, _) in mirrorbox_report::readme::REGIONS {
        assert!(
            text.contains(&format!("<!-- generated: {id} -->")),
            "neither README.md nor docs/methods.md has the generated region {id:?}"
        );
    }
}

#[test]
fn a_changed_figure_in_a_region_is_caught_and_named() {
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    // Change the first digit inside the first region.
    let start = readme.find("<!-- generated: ").expect("a region");
    let body = start + readme[start..].find('\n').unwrap();
    let digit = body + readme[body..].find(|c: char| c.is_ascii_digit()).unwrap();
    let mut changed = readme.clone();
    let d = readme.as_bytes()[digit];
    changed.replace_range(digit..digit + 1, if d == b'9' { "8" } else { "9" });
    let dir = tempfile::tempdir().unwrap();
    let copy = dir.path().join("README.md");
    std::fs::write(&copy, changed).unwrap();
    let reports = repo().join("reports");
    let out = mirrorbox(
        &[
            "readme",
            "--check",
            copy.to_str().unwrap(),
            "--reports",
            reports.to_str().unwrap(),
        ],
        &[],
    );
    assert_eq!(out.code, 1, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stderr
            .contains("disagrees with the committed reports in 1 region"),
        "{}",
        out.stderr
    );
    // Filling it restores the README exactly.
    let out = mirrorbox(
        &[
            "readme",
            copy.to_str().unwrap(),
            "--reports",
            reports.to_str().unwrap(),
        ],
        &[],
    );
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert_eq!(std::fs::read_to_string(&copy).unwrap(), readme);
}
