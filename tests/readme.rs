//! The README's, the book's and the docs' numbers are the committed reports' numbers: every
//! generated region of `README.md`, `docs/methods.md` and the book's chapters
//! (`docs/book/src/*.md`) must be what `mirrorbox readme` makes from `reports/` (issue #13),
//! and the command-line reference (`docs/book/src/cli.md`) what the program's own `--help`
//! says. The README stays a front door, and every relative link of the README, the book and
//! the docs points at a file (and heading) that exists.

use crate::common::{mirrorbox, repo};
use std::path::{Path, PathBuf};

/// The book's chapters, in name order.
fn book_chapters() -> Vec<PathBuf> {
    let dir = repo().join("docs/book/src");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    files.sort();
    files
}

/// Every file `mirrorbox readme` fills by default.
fn filled_files() -> Vec<PathBuf> {
    let mut files = vec![repo().join("README.md"), repo().join("docs/methods.md")];
    files.extend(book_chapters());
    files
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn the_readme_agrees_with_the_committed_reports() {
    let out = mirrorbox(&["readme", "--check"], &[]);
    assert_eq!(
        out.code, 0,
        "{}{}\n(after changing a report or a flag, run `mirrorbox readme` and commit README.md, \
         docs/methods.md and docs/book/src/)",
        out.stdout, out.stderr
    );
    // The book's chapters are checked too, each by name.
    for chapter in book_chapters() {
        let name = chapter.strip_prefix(repo()).unwrap().display().to_string();
        assert!(
            out.stdout
                .contains(&format!("{name}: every generated region agrees")),
            "{name} was not checked:\n{}",
            out.stdout
        );
    }
    // Every region the generator knows is used, so no report figure is quoted by hand.
    let text: String = filled_files().iter().map(|f| read(f)).collect();
    for region in mirrorbox_experiments::regions() {
        let id = region.id;
        assert!(
            text.contains(&format!("<!-- generated: {id} -->")),
            "none of README.md, docs/methods.md and docs/book/src/*.md has the generated region {id:?}"
        );
    }
    // The command-line reference is generated from the program's own `--help`.
    let cli = read(&repo().join("docs/book/src/cli.md"));
    assert!(
        cli.contains("<!-- generated: cli -->"),
        "cli.md has no `cli` region"
    );
    for command in ["check", "trace", "render", "sweep", "readme", "view"] {
        assert!(
            cli.contains(&format!("## `mirrorbox {command}`")),
            "cli.md has no section for `mirrorbox {command}`"
        );
    }
    assert!(
        !cli.contains("## `mirrorbox render-worker`"),
        "the hidden internal subcommand is not documented"
    );
}

#[test]
fn a_changed_figure_in_a_region_is_caught_and_named() {
    let readme = read(&repo().join("README.md"));
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

#[test]
fn a_changed_command_line_reference_is_caught_and_named() {
    let cli = read(&repo().join("docs/book/src/cli.md"));
    // A flag documented by hand that the program does not have.
    let usage = cli
        .find("Usage: mirrorbox render")
        .expect("render's usage line");
    let mut changed = cli.clone();
    changed.insert_str(usage, "      --no-such-flag  typed by hand\n");
    let dir = tempfile::tempdir().unwrap();
    let copy = dir.path().join("cli.md");
    std::fs::write(&copy, changed).unwrap();
    let out = mirrorbox(&["readme", "--check", copy.to_str().unwrap()], &[]);
    assert_eq!(out.code, 1, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stderr.contains("in 1 region") && out.stderr.contains("region \"cli\""),
        "{}",
        out.stderr
    );
    assert!(out.stderr.contains("--no-such-flag"), "{}", out.stderr);
    // Filling it restores the page exactly.
    let out = mirrorbox(&["readme", copy.to_str().unwrap()], &[]);
    assert_eq!(out.code, 0, "{}", out.stderr);
    assert_eq!(std::fs::read_to_string(&copy).unwrap(), cli);
}

#[test]
fn the_readme_is_a_front_door() {
    let lines = read(&repo().join("README.md")).lines().count();
    assert!(
        lines <= 200,
        "README.md has {lines} lines: at most 200 (an experiment's text goes in its book chapter)"
    );
    // Every chapter is in the book's table of contents.
    let summary = read(&repo().join("docs/book/src/SUMMARY.md"));
    for chapter in book_chapters() {
        let name = chapter.file_name().unwrap().to_str().unwrap();
        if name != "SUMMARY.md" {
            assert!(
                summary.contains(&format!("]({name})")),
                "docs/book/src/SUMMARY.md does not list {name}"
            );
        }
    }
}

/// The relative link targets of a Markdown text with their line numbers: `[label](target)`
/// and `![alt](target)`, outside fenced code blocks; targets with a scheme are left out.
fn relative_links(text: &str) -> Vec<(usize, String)> {
    let mut links = Vec::new();
    let mut fenced = false;
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        let mut rest = line;
        while let Some(at) = rest.find("](") {
            let after = &rest[at + 2..];
            let Some(end) = after.find(')') else { break };
            let target = &after[..end];
            if !target.is_empty()
                && !target.contains(' ')
                && !target.contains("://")
                && !target.starts_with("mailto:")
            {
                links.push((i + 1, target.to_string()));
            }
            rest = &after[end..];
        }
    }
    links
}

/// A heading's anchor as GitHub and mdBook make it: lower case, spaces to hyphens, other
/// punctuation dropped.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

fn anchors(markdown: &str) -> Vec<String> {
    let mut fenced = false;
    let mut out = Vec::new();
    for line in markdown.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        } else if !fenced && line.starts_with('#') {
            out.push(anchor(line.trim_start_matches('#')));
        }
    }
    out
}

#[test]
fn every_relative_link_points_at_a_file_that_exists() {
    let mut files = vec![repo().join("README.md"), repo().join("CONTRIBUTING.md")];
    files.extend(book_chapters());
    let docs = repo().join("docs");
    for entry in std::fs::read_dir(&docs).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|x| x == "md") {
            files.push(path);
        }
    }
    let mut broken = Vec::new();
    for file in &files {
        let text = read(file);
        let dir = file.parent().unwrap();
        for (line, target) in relative_links(&text) {
            let (path, fragment) = match target.split_once('#') {
                Some((p, f)) => (p, Some(f)),
                None => (target.as_str(), None),
            };
            let resolved = if path.is_empty() {
                file.clone()
            } else {
                dir.join(path)
            };
            let name = file.strip_prefix(repo()).unwrap().display().to_string();
            if !resolved.exists() {
                broken.push(format!("{name}:{line}: {target} (no such file)"));
                continue;
            }
            if let Some(fragment) = fragment
                && resolved.extension().is_some_and(|x| x == "md")
                && !anchors(&read(&resolved)).iter().any(|a| a == fragment)
            {
                broken.push(format!("{name}:{line}: {target} (no such heading)"));
            }
        }
    }
    assert!(
        broken.is_empty(),
        "broken relative links:\n  {}",
        broken.join("\n  ")
    );
}

#[test]
fn links_and_anchors_are_read_as_markdown_writes_them() {
    let text = "See [`a.md`](a.md#x) and ![i](../b.png), not [w](https://e.org).\n\
                ```\n[c](in-code.md)\n```\n[d](c.md) [e](f g)\n";
    assert_eq!(
        relative_links(text),
        vec![
            (1, "a.md#x".to_string()),
            (1, "../b.png".to_string()),
            (5, "c.md".to_string())
        ]
    );
    assert_eq!(
        anchor(" Colour targets: RGBA32F, or RGBA16F"),
        "colour-targets-rgba32f-or-rgba16f"
    );
    assert_eq!(anchor(" The `cli` region"), "the-cli-region");
}

/// Issue 54: mdBook builds only `docs/book/src/`, so every image a chapter shows must be a
/// file inside it — a repository figure linked as `figures/<path>` and its copy up to date
/// (`mirrorbox readme` makes it), none left over.
#[test]
fn every_image_of_the_book_resolves_inside_its_source() {
    let root = repo();
    let s = mirrorbox_report::book_figures::sync(&root, &root.join("docs/book/src"), true).unwrap();
    assert!(
        s.broken.is_empty(),
        "links out of the book or to nothing: {:?}",
        s.broken
    );
    assert!(
        s.written.is_empty(),
        "copies missing or stale (run mirrorbox readme): {:?}",
        s.written
    );
    assert!(
        s.removed.is_empty(),
        "copies no chapter links: {:?}",
        s.removed
    );
    // And the book shows figures at all (the links were once all outside it).
    let table1 = std::fs::read_to_string(root.join("docs/book/src/table1.md")).unwrap();
    assert!(
        mirrorbox_report::book_figures::image_links(&table1)
            .iter()
            .any(|l| l.starts_with("figures/"))
    );
}

/// A bad later file (an unterminated region) leaves the earlier files as they were: every
/// file is filled before any is written. Before, the earlier file was already rewritten.
#[test]
fn a_bad_file_leaves_every_file_unwritten() {
    let cli = read(&repo().join("docs/book/src/cli.md"));
    let usage = cli
        .find("Usage: mirrorbox render")
        .expect("render's usage line");
    let mut stale = cli.clone();
    stale.insert_str(usage, "      --no-such-flag  typed by hand\n");
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.md"), dir.path().join("b.md"));
    std::fs::write(&a, &stale).unwrap();
    std::fs::write(&b, "# B\n\n<!-- generated: cli -->\nnever ended\n").unwrap();
    let out = mirrorbox(&["readme", a.to_str().unwrap(), b.to_str().unwrap()], &[]);
    assert_eq!(out.code, 2, "{}{}", out.stdout, out.stderr);
    assert!(
        out.stderr.contains("b.md") && out.stderr.contains("no file was written"),
        "{}",
        out.stderr
    );
    assert_eq!(std::fs::read_to_string(&a).unwrap(), stale);
}

/// The Markdown files a user reads: every `*.md` of the repository but the generated reports,
/// build outputs and installed packages.
fn markdown_files() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let skip = ["target", "reports", "node_modules", ".venv", ".git"];
        for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_str().unwrap_or("");
            if path.is_dir() {
                // mdBook's output (docs/book/book) is built, not written.
                if !skip.contains(&name) && !path.ends_with("docs/book/book") {
                    walk(&path, out);
                }
            } else if name.ends_with(".md") {
                out.push(path);
            }
        }
    }
    let mut files = Vec::new();
    walk(&repo(), &mut files);
    files.sort();
    files
}

/// The commands a Markdown text shows, with their line numbers: each line of a fenced block
/// (a line ending in `\` joined to the next), and each code span of a paragraph (a span may
/// break across lines). Generated regions are records of past runs, quoted as they ran, and
/// left out.
fn shown_commands(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let (mut generated, mut fenced) = (false, false);
    let mut paragraph: Vec<&str> = Vec::new();
    let mut first_line = 0;
    let mut continued = String::new();
    let spans = |paragraph: &mut Vec<&str>, first_line: usize, out: &mut Vec<_>| {
        let text = paragraph.join("\n");
        let mut rest = text.as_str();
        while let Some(open) = rest.find('`') {
            let Some(close) = rest[open + 1..].find('`') else {
                break;
            };
            let line = first_line + text[..text.len() - rest.len() + open].matches('\n').count();
            out.push((line, rest[open + 1..open + 1 + close].to_string()));
            rest = &rest[open + close + 2..];
        }
        paragraph.clear();
    };
    for (i, line) in text.lines().enumerate() {
        let number = i + 1;
        if line.contains("<!-- generated:") {
            spans(&mut paragraph, first_line, &mut out);
            generated = true;
        } else if line.contains("<!-- end generated") {
            generated = false;
        } else if generated {
        } else if line.trim_start().starts_with("```") {
            spans(&mut paragraph, first_line, &mut out);
            fenced = !fenced;
            // A block's last line ending in `\` continues nothing after the block.
            continued.clear();
        } else if fenced {
            match line.trim_end().strip_suffix('\\') {
                Some(head) => continued.push_str(head),
                None => out.push((number, std::mem::take(&mut continued) + line)),
            }
        } else if line.trim().is_empty() {
            spans(&mut paragraph, first_line, &mut out);
        } else {
            if paragraph.is_empty() {
                first_line = number;
            }
            paragraph.push(line);
        }
    }
    spans(&mut paragraph, first_line, &mut out);
    out
}

/// What is wrong with the `mirrorbox` calls in one command: a subcommand the program lacks,
/// a long option its subcommand's `--help` does not list, an experiment not in the registry.
fn wrong_calls(
    command: &str,
    options: &std::collections::BTreeMap<String, String>,
    experiments: &[&str],
) -> Vec<String> {
    let words: Vec<&str> = command.split_whitespace().collect();
    let mut wrong = Vec::new();
    for (i, word) in words.iter().enumerate() {
        if *word != "mirrorbox" && !word.ends_with("/mirrorbox") {
            continue;
        }
        let Some(sub) = words.get(i + 1) else {
            continue;
        };
        let is_name = |w: &str| {
            w.starts_with(|c: char| c.is_ascii_lowercase())
                && w.chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
        };
        if !is_name(sub) {
            continue;
        }
        let Some(help) = options.get(*sub) else {
            wrong.push(format!("`{sub}` is not a subcommand"));
            continue;
        };
        // The call's words, up to the end of the shell command.
        let args: Vec<&str> = words[i + 2..]
            .iter()
            .take_while(|w| !["|", "&&", "||", ";", "#"].contains(w) && !w.starts_with('>'))
            .copied()
            .collect();
        for arg in &args {
            if let Some(flag) = arg.strip_prefix("--") {
                let flag: String = flag
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
                    .collect();
                let listed = help.match_indices(&format!("--{flag}")).any(|(at, _)| {
                    !help[at + 2 + flag.len()..]
                        .starts_with(|c: char| c.is_ascii_alphanumeric() || c == '-')
                });
                if !listed {
                    wrong.push(format!("`{sub}` has no --{flag}"));
                }
            }
        }
        if *sub == "experiment"
            && let Some(name) = args.first().filter(|a| is_name(a))
            && !experiments.contains(name)
        {
            wrong.push(format!("no experiment `{name}`"));
        }
    }
    wrong
}

/// Every `mirrorbox` command the docs show is one the program takes: its subcommand, its long
/// options and an experiment's name. The preset subcommands (`mirrorbox table1`) had been
/// removed while a chapter and the Slurm docs still showed them.
#[test]
fn every_command_the_docs_show_is_one_the_program_takes() {
    let top = mirrorbox(&["--help"], &[]).stdout;
    let listed = top
        .split("Commands:")
        .nth(1)
        .and_then(|s| s.split("Options:").next())
        .expect("--help lists the commands");
    let options: std::collections::BTreeMap<String, String> = listed
        .lines()
        .filter_map(|l| l.strip_prefix("  ")?.split_whitespace().next())
        .map(|sub| (sub.to_string(), mirrorbox(&[sub, "--help"], &[]).stdout))
        .collect();
    assert!(options.len() > 10 && options["trace"].contains("--spp"));
    let experiments: Vec<&str> = mirrorbox_experiments::EXPERIMENTS
        .iter()
        .map(|e| e.name)
        .collect();
    let mut wrong = Vec::new();
    let files = markdown_files();
    for file in &files {
        let name = file.strip_prefix(repo()).unwrap().display().to_string();
        for (line, command) in shown_commands(&read(file)) {
            for w in wrong_calls(&command, &options, &experiments) {
                wrong.push(format!("{name}:{line}: {w}: {command}"));
            }
        }
    }
    assert!(files.len() > 30, "{} Markdown files", files.len());
    assert!(
        wrong.is_empty(),
        "commands the program does not take:\n  {}",
        wrong.join("\n  ")
    );
}

#[test]
fn commands_are_found_in_spans_blocks_and_across_lines() {
    let text = "Run `mirrorbox\ntrace x` and `a`.\n\n```sh\nmirrorbox sweep s \\\n  --frames 3\n```\n\
                <!-- generated: r -->\n`mirrorbox table1`\n<!-- end generated: r -->\n";
    assert_eq!(
        shown_commands(text),
        vec![
            (1, "mirrorbox\ntrace x".to_string()),
            (2, "a".to_string()),
            (6, "mirrorbox sweep s   --frames 3".to_string()),
        ]
    );
    let options = [("sweep", "--frames <N>\n--shard"), ("experiment", "--out")]
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .into();
    let calls = |c| wrong_calls(c, &options, &["table1"]);
    assert!(calls("target/release/mirrorbox sweep a --frames 3 | tee --fr").is_empty());
    assert_eq!(
        calls("mirrorbox table1 --out x"),
        ["`table1` is not a subcommand"]
    );
    assert_eq!(calls("mirrorbox sweep --fram 2"), ["`sweep` has no --fram"]);
    assert_eq!(
        calls("mirrorbox sweep --frames-x"),
        ["`sweep` has no --frames-x"]
    );
    assert_eq!(
        calls("mirrorbox experiment cluster"),
        ["no experiment `cluster`"]
    );
}
