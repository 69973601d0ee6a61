//! The book's figures inside the book (issue 54): mdBook builds only what lies under
//! `docs/book/src/`, so a chapter's image links outside it showed nothing in the built book.
//! A chapter links a figure of the repository as `figures/<path from the repository root>`
//! (`![…](figures/reports/table1/plot_flip_vs_ms.svg)`), and `mirrorbox readme` copies each
//! such file to `docs/book/src/figures/<path>` ([`sync`]), removing copies no chapter links
//! any more; `readme --check` and the tests fail where a copy is missing or stale.

use std::path::{Path, PathBuf};

/// The folder of the copies, inside the book's source.
pub const FIGURES: &str = "figures";

/// Every image a chapter links (`![alt](target)`, the target up to its `)`), in order.
pub fn image_links(markdown: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = markdown;
    while let Some(i) = rest.find("![") {
        rest = &rest[i + 2..];
        let Some(close) = rest.find("](") else { break };
        let after = &rest[close + 2..];
        let Some(end) = after.find(')') else { break };
        out.push(after[..end].trim().to_string());
        rest = &after[end..];
    }
    out
}

/// What [`sync`] found or did: the copies written (or, checking, out of date) and removed
/// (or, checking, left over), and the links that resolve to nothing.
#[derive(Debug, Default, PartialEq)]
pub struct Synced {
    pub written: Vec<PathBuf>,
    pub removed: Vec<PathBuf>,
    pub broken: Vec<String>,
}

impl Synced {
    pub fn is_clean(&self) -> bool {
        self.written.is_empty() && self.removed.is_empty() && self.broken.is_empty()
    }
}

/// Brings `book_src/figures/` in line with the chapters (`book_src/*.md`): each
/// `figures/<path>` link a copy of `root/<path>`, nothing else. With `check`, changes
/// nothing and reports what it would change. A link elsewhere inside the book must resolve
/// there; a link out of the book is broken.
pub fn sync(root: &Path, book_src: &Path, check: bool) -> std::io::Result<Synced> {
    let mut out = Synced::default();
    let mut wanted: Vec<PathBuf> = Vec::new();
    let mut chapters: Vec<PathBuf> = std::fs::read_dir(book_src)?
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    chapters.sort();
    for chapter in &chapters {
        let name = chapter.file_name().unwrap_or_default().to_string_lossy();
        for link in image_links(&std::fs::read_to_string(chapter)?) {
            if link.contains("://") {
                continue;
            }
            let Some(rel) = link.strip_prefix(&format!("{FIGURES}/")) else {
                if link.starts_with("..") || !book_src.join(&link).is_file() {
                    out.broken.push(format!(
                        "{name}: {link} (link a repository file as {FIGURES}/<its path>)"
                    ));
                }
                continue;
            };
            let source = root.join(rel);
            if rel.split('/').any(|c| c == "..") || !source.is_file() {
                out.broken
                    .push(format!("{name}: {link} ({} is no file)", source.display()));
                continue;
            }
            let copy = book_src.join(FIGURES).join(rel);
            if !wanted.contains(&copy) {
                wanted.push(copy.clone());
            }
            let same =
                std::fs::read(&copy).is_ok_and(|c| std::fs::read(&source).is_ok_and(|s| s == c));
            if !same {
                if !check {
                    std::fs::create_dir_all(copy.parent().unwrap_or(book_src))?;
                    std::fs::copy(&source, &copy)?;
                }
                out.written.push(copy);
            }
        }
    }
    let mut present = Vec::new();
    collect_files(&book_src.join(FIGURES), &mut present)?;
    for file in present.into_iter().filter(|f| !wanted.contains(f)) {
        if !check {
            std::fs::remove_file(&file)?;
        }
        out.removed.push(file);
    }
    Ok(out)
}

fn collect_files(dir: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            collect_files(&p, out)?;
        } else {
            out.push(p);
        }
    }
    out.sort();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn image_links_are_found_and_other_links_are_not() {
        let md = "![a](figures/x.svg) text [b](c.md) ![d e](../y.png)\n![](z.png)";
        assert_eq!(image_links(md), ["figures/x.svg", "../y.png", "z.png"]);
    }

    #[test]
    fn figures_are_copied_checked_and_pruned() {
        let root = tempfile::tempdir().unwrap();
        let src = root.path().join("docs/book/src");
        std::fs::create_dir_all(&src).unwrap();
        std::fs::create_dir_all(root.path().join("reports/t")).unwrap();
        std::fs::write(root.path().join("reports/t/p.svg"), "<svg/>").unwrap();
        std::fs::write(src.join("c.md"), "# C\n\n![p](figures/reports/t/p.svg)\n").unwrap();
        // Checking first: the copy is missing.
        let s = sync(root.path(), &src, true).unwrap();
        assert_eq!(s.written, [src.join("figures/reports/t/p.svg")]);
        assert!(!src.join("figures/reports/t/p.svg").exists());
        // Writing makes it, and then all is clean.
        sync(root.path(), &src, false).unwrap();
        assert!(sync(root.path(), &src, true).unwrap().is_clean());
        // A changed source makes the copy stale; an unlinked copy is left over.
        std::fs::write(root.path().join("reports/t/p.svg"), "<svg></svg>").unwrap();
        std::fs::write(src.join("figures/old.png"), "x").unwrap();
        let s = sync(root.path(), &src, true).unwrap();
        assert_eq!(s.written.len(), 1);
        assert_eq!(s.removed, [src.join("figures/old.png")]);
        // A link out of the book, and one to a missing file, are broken.
        std::fs::write(
            src.join("d.md"),
            "![q](../../../reports/t/p.svg) ![r](figures/none.svg)",
        )
        .unwrap();
        let s = sync(root.path(), &src, false).unwrap();
        assert_eq!(s.broken.len(), 2, "{:?}", s.broken);
        assert!(!src.join("figures/old.png").exists());
    }
}
