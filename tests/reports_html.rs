//! Every HTML report a reader opens fits the page (issue 38): loaded in headless Chromium at
//! 1280 px, no report scrolls sideways (wide tables scroll inside their own box) and no image
//! is broken. The page is measured from a wrapper that loads the report in an iframe and
//! writes what it found into its own DOM, which Chromium dumps. Without
//! `chromium-headless-shell` the tests fail, unless `MIRRORBOX_TEST_SKIP` names `chromium`
//! (`mirrorbox_testing`).

use crate::common::repo;
use std::path::{Path, PathBuf};
use std::process::Command;

const BROWSER: &str = "chromium-headless-shell";

/// Whether the browser is installed; where not, a failure, or `false` where
/// `MIRRORBOX_TEST_SKIP` names `chromium`.
fn browser_present() -> bool {
    mirrorbox_testing::require(
        mirrorbox_testing::CHROMIUM,
        mirrorbox_testing::on_path(BROWSER),
        &format!("{BROWSER} is not installed"),
    )
}

fn html_reports() -> Vec<PathBuf> {
    let reports = repo().join("reports");
    let mut out = vec![reports.join("index.html")];
    for dir in [reports.clone(), reports.join("gpu")] {
        for e in std::fs::read_dir(&dir).unwrap().flatten() {
            let p = e.path().join("report.html");
            if p.is_file() {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Loads `page` at 1280 px in Chromium; returns what the wrapper's script found:
/// `ok`, or the overflow and the broken images.
fn measure(page: &Path, scratch: &Path) -> String {
    let url = format!("file://{}", page.canonicalize().unwrap().display());
    let wrapper = scratch.join("measure.html");
    std::fs::write(
        &wrapper,
        format!(
            r#"<!DOCTYPE html><html><body style="margin:0">
<iframe id="f" src="{url}" style="width:1280px;height:900px;border:0"></iframe>
<pre id="out">pending</pre>
<script>
document.getElementById('f').onload = () => {{
  const d = document.getElementById('f').contentDocument;
  const problems = [];
  const over = d.documentElement.scrollWidth - d.documentElement.clientWidth;
  if (over > 0) problems.push('overflows by ' + over + ' px');
  for (const img of d.images) {{
    if (!(img.complete && img.naturalWidth > 0)) problems.push('broken image ' + img.alt);
  }}
  document.getElementById('out').textContent = problems.length ? problems.join('; ') : 'ok';
}};
</script></body></html>"#
        ),
    )
    .unwrap();
    let out = Command::new(BROWSER)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--allow-file-access-from-files",
            "--window-size=1300,1000",
            "--virtual-time-budget=10000",
            "--dump-dom",
        ])
        .arg(format!("file://{}", wrapper.display()))
        .output()
        .unwrap_or_else(|e| {
            panic!("cannot run {BROWSER} ({e}): scripts/install-system-deps.sh installs it")
        });
    let dom = String::from_utf8_lossy(&out.stdout);
    dom.split("<pre id=\"out\">")
        .nth(1)
        .and_then(|s| s.split("</pre>").next())
        .unwrap_or("no result from the page")
        .to_string()
}

#[test]
fn every_html_report_fits_1280_px_and_shows_its_images() {
    if !browser_present() {
        return;
    }
    let scratch = tempfile::tempdir().unwrap();
    let reports = html_reports();
    assert!(reports.len() >= 10, "{reports:?}");
    let failures: Vec<String> = reports
        .iter()
        .filter_map(|p| {
            let found = measure(p, scratch.path());
            (found != "ok").then(|| format!("{}: {found}", p.display()))
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn the_measurement_sees_an_overflow_and_a_broken_image() {
    if !browser_present() {
        return;
    }
    // The check must be able to fail: a page wider than 1280 px with a missing image.
    let scratch = tempfile::tempdir().unwrap();
    let page = scratch.path().join("wide.html");
    std::fs::write(
        &page,
        r#"<html><body><div style="width:2000px">wide</div><img src="missing.png" alt="gone"></body></html>"#,
    )
    .unwrap();
    let found = measure(&page, scratch.path());
    assert!(found.contains("overflows"), "{found}");
    assert!(found.contains("broken image gone"), "{found}");
}
