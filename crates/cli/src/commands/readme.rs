//! `mirrorbox readme [--check]`: fills the generated regions (`<!-- generated: ID -->` …
//! `<!-- end generated: ID -->`) of the README, `docs/methods.md` and the book's chapters
//! (`docs/book/src/*.md`) from the committed reports, so every figure their prose quotes is
//! the report's own (`mirrorbox_report::readme`), and the region `cli` from this command
//! line's own argument parser, so the command-line reference is the `--help` users see, and
//! each experiment's region `experiment-NAME` from its row of the registry
//! (`mirrorbox-experiments`), whose chapter must hold it.

use crate::Failure;
use mirrorbox_report::readme::{
    Region, RegionSource, fill_with, known_regions, stale_regions_with,
};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct Args {
    /// Do not write: exit 1 if a region differs from what the reports give, naming it.
    #[arg(long)]
    check: bool,
    /// The Markdown files to fill (their regions name the reports they quote). Default:
    /// README.md, docs/methods.md, reports/advise/README.md and every docs/book/src/*.md.
    files: Vec<PathBuf>,
    /// The folder of the committed reports.
    #[arg(long, default_value = "reports")]
    reports: PathBuf,
}

/// The files filled when none is named, relative to the repository root: the README, the
/// methods' page, and the advisor's reports, whose answers have no sweep report of their own
/// for the overview to list (`reports/advise/README.md`).
const DEFAULT_FILES: [&str; 3] = ["README.md", "docs/methods.md", "reports/advise/README.md"];
/// The book's chapters: every `*.md` directly in this folder is filled too.
pub const BOOK_SOURCE: &str = "docs/book/src";

/// The region that holds the command-line reference (`docs/book/src/cli.md`).
pub const CLI_REGION: &str = "cli";

/// The width clap lays the help out for, fixed so the reference does not depend on the
/// terminal that runs `mirrorbox readme`.
const HELP_WIDTH: usize = 100;

pub fn run(args: &Args) -> Result<(), Failure> {
    let files = if args.files.is_empty() {
        default_files()?
    } else {
        args.files.clone()
    };
    let mut extra = vec![Region {
        id: CLI_REGION,
        text: cli_reference(),
    }];
    // Each experiment's region in its chapter, from its row of the registry.
    for e in mirrorbox_experiments::EXPERIMENTS {
        extra.push(Region {
            id: Box::leak(e.region_id().into_boxed_str()),
            text: e.region_text(),
        });
    }
    // The regions made from the reports: the generic ones and each experiment's.
    let sources = mirrorbox_experiments::regions();
    if args.files.is_empty() {
        check_chapters()?;
    }
    // Every file is tried; bad input (a malformed region, a missing report) decides exit 2
    // over a stale region's exit 1.
    let (mut messages, mut bad_input) = (Vec::new(), false);
    let mut fills = Vec::new();
    for file in &files {
        match one(file, args, &extra, &sources) {
            Ok(fill) => fills.extend(fill),
            Err(Failure::BadInput(m)) => {
                bad_input = true;
                messages.push(m);
            }
            Err(Failure::Other(m)) => messages.push(m),
        }
    }
    // Written only once every file is filled: a bad later file leaves the earlier ones as
    // they were (no half-done run).
    if bad_input && !fills.is_empty() {
        messages.push("no file was written".into());
    } else {
        for fill in &fills {
            if let Err(m) = fill.write(&args.reports) {
                messages.push(m);
            }
        }
    }
    if args.files.is_empty() {
        book_figures(args.check, &mut messages, &mut bad_input)?;
    }
    if !args.check {
        println!("regions known: {}", known_regions(&extra, &sources));
    }
    match (messages.is_empty(), bad_input) {
        (true, _) => Ok(()),
        (false, true) => Err(Failure::BadInput(messages.join("\n"))),
        (false, false) => Err(Failure::Other(messages.join("\n"))),
    }
}

/// The book's figures copied inside it (`mirrorbox_report::book_figures`): written, or with
/// `check` compared; a stale copy is a message (exit 1), a broken link bad input (exit 2).
fn book_figures(
    check: bool,
    messages: &mut Vec<String>,
    bad_input: &mut bool,
) -> Result<(), Failure> {
    use mirrorbox_report::book_figures::sync;
    let s = sync(Path::new("."), Path::new(BOOK_SOURCE), check)
        .map_err(|e| Failure::Other(format!("{BOOK_SOURCE}/figures: {e}")))?;
    for b in &s.broken {
        *bad_input = true;
        messages.push(format!("{BOOK_SOURCE}/{b}"));
    }
    if check {
        for p in &s.written {
            messages.push(format!(
                "{}: missing or stale (mirrorbox readme copies it)",
                p.display()
            ));
        }
        for p in &s.removed {
            messages.push(format!(
                "{}: no chapter links it (mirrorbox readme removes it)",
                p.display()
            ));
        }
    } else if !s.written.is_empty() || !s.removed.is_empty() {
        println!(
            "{BOOK_SOURCE}/figures: {} figure(s) copied, {} removed",
            s.written.len(),
            s.removed.len()
        );
    }
    Ok(())
}

/// Every experiment of the registry has its chapter in the book, listed in its `SUMMARY.md`,
/// holding the experiment's region: an experiment cannot be added without its chapter.
fn check_chapters() -> Result<(), Failure> {
    let book = Path::new(BOOK_SOURCE);
    let summary = std::fs::read_to_string(book.join("SUMMARY.md"))
        .map_err(|e| Failure::BadInput(format!("{}/SUMMARY.md: {e}", book.display())))?;
    let mut missing = Vec::new();
    for e in mirrorbox_experiments::EXPERIMENTS {
        let chapter = book.join(e.chapter);
        let marker = format!("<!-- generated: {} -->", e.region_id());
        match std::fs::read_to_string(&chapter) {
            Err(_) => missing.push(format!(
                "experiment {}: its chapter {} does not exist",
                e.name,
                chapter.display()
            )),
            Ok(text) if !text.contains(&marker) => missing.push(format!(
                "experiment {}: {} lacks its region (add `{marker}` and `<!-- end generated: {} -->`)",
                e.name,
                chapter.display(),
                e.region_id()
            )),
            Ok(_) => {}
        }
        if !summary.contains(&format!("]({})", e.chapter)) {
            missing.push(format!(
                "experiment {}: {}/SUMMARY.md does not list its chapter {}",
                e.name,
                book.display(),
                e.chapter
            ));
        }
    }
    if missing.is_empty() {
        Ok(())
    } else {
        Err(Failure::BadInput(missing.join("\n")))
    }
}

/// README.md, docs/methods.md and the book's chapters in name order (run from the
/// repository root).
fn default_files() -> Result<Vec<PathBuf>, Failure> {
    let mut files: Vec<PathBuf> = DEFAULT_FILES.iter().map(PathBuf::from).collect();
    let book = Path::new(BOOK_SOURCE);
    let entries = std::fs::read_dir(book).map_err(|e| {
        Failure::BadInput(format!(
            "{}: {e} (run `mirrorbox readme` from the repository root, or name the files)",
            book.display()
        ))
    })?;
    let mut chapters = Vec::new();
    for entry in entries {
        let path = entry
            .map_err(|e| Failure::Other(format!("{}: {e}", book.display())))?
            .path();
        if path.extension().is_some_and(|x| x == "md") && path.is_file() {
            chapters.push(path);
        }
    }
    chapters.sort();
    files.extend(chapters);
    Ok(files)
}

/// The command-line reference: `mirrorbox --help`, then every visible subcommand's `--help`
/// under its own heading, as clap renders it at [`HELP_WIDTH`] columns, without styling.
pub fn cli_reference() -> String {
    let mut cli = <crate::Cli as clap::CommandFactory>::command().term_width(HELP_WIDTH);
    cli.build();
    let mut out = String::new();
    let mut section = |title: &str, help: String| {
        out.push_str(&format!("## `{title}`\n\n```text\n"));
        for line in help.trim_end().lines() {
            out.push_str(line.trim_end());
            out.push('\n');
        }
        out.push_str("```\n\n");
    };
    let top = cli.render_long_help().to_string();
    section("mirrorbox", top);
    let name = cli.get_name().to_string();
    for sub in cli.get_subcommands_mut() {
        if sub.is_hide_set() || sub.get_name() == "help" {
            continue;
        }
        let title = format!("{name} {}", sub.get_name());
        let mut sub = sub.clone().term_width(HELP_WIDTH);
        let help = sub.render_long_help().to_string();
        section(&title, help);
    }
    format!("{}\n", out.trim_end())
}

/// Checks one file, or computes its filled text (written by the caller once every file is
/// filled); a malformed region or a missing report is bad input (exit 2).
fn one(
    file: &Path,
    args: &Args,
    extra: &[Region],
    sources: &[RegionSource],
) -> Result<Option<Fill>, Failure> {
    let bad = |e: &dyn std::fmt::Display| Failure::BadInput(format!("{}: {e}", file.display()));
    let text = mirrorbox_files::read_bounded_text(file, MAX_README_BYTES, "a Markdown file")
        .map_err(|e| bad(&e))?;
    if args.check {
        let stale =
            stale_regions_with(&text, &args.reports, extra, sources).map_err(|e| bad(&e))?;
        if stale.is_empty() {
            println!(
                "{}: every generated region agrees with {}",
                file.display(),
                args.reports.display()
            );
            return Ok(None);
        }
        let lines: Vec<String> = stale
            .iter()
            .map(|(id, have, want)| {
                format!("region {id:?}: the file has\n    {have}\n  the reports give\n    {want}")
            })
            .collect();
        return Err(Failure::Other(format!(
            "{} disagrees with the committed reports in {}:\n  {}\nrun `mirrorbox readme` to regenerate the regions",
            file.display(),
            crate::count(stale.len(), "region"),
            lines.join("\n  ")
        )));
    }
    let filled = fill_with(&text, &args.reports, extra, sources).map_err(|e| bad(&e))?;
    Ok(Some(Fill {
        file: file.to_path_buf(),
        changed: filled != text,
        text: filled,
    }))
}

/// A file's new text, computed before any file is written.
struct Fill {
    file: PathBuf,
    text: String,
    changed: bool,
}

impl Fill {
    fn write(&self, reports: &Path) -> Result<(), String> {
        if self.changed {
            mirrorbox_files::write_atomically(&self.file, self.text.as_bytes())
                .map_err(|e| e.to_string())?;
        }
        println!(
            "{}: {} from {}",
            self.file.display(),
            if self.changed {
                "generated regions filled"
            } else {
                "generated regions already up to date"
            },
            reports.display(),
        );
        Ok(())
    }
}

/// A README is text of a few hundred KB at most; the bound keeps a mistaken path from being
/// read whole.
const MAX_README_BYTES: u64 = 16 << 20;
