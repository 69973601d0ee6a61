//! What a test does when a component it needs is missing (issue 50): it **fails**, unless
//! the person running the tests named that component as one they agree to skip.
//!
//! The contract, shared by every test crate of the workspace (`scripts/test.sh` holds the
//! other half):
//!
//! - `MIRRORBOX_TEST_SKIP` is a comma-separated list of component names the user agrees to
//!   skip: [`CORPUS`], [`XVFB`], [`XDOTOOL`], [`SLURM`] (also covers not being root),
//!   [`MITSUBA`], [`CHROMIUM`], [`RAYTRACING`] (the adapter lacks ray queries), [`WEB`] — the list
//!   `scripts/lib/skip.sh` checks the variable against. CI sets none. What else a test needs
//!   (Mesa's lavapipe, its GL backend and clip distances) has no opt-out: its absence fails.
//! - A test whose component is missing calls [`require`] with `present: false`:
//!   - if the component is in `MIRRORBOX_TEST_SKIP`, it prints
//!     `skipped: <component>: <reason>` to stderr, appends one line
//!     `<component>\t<test name>\t<reason>` to the file named by `MIRRORBOX_SKIP_LOG` (when
//!     set; the test script lists every line in its summary), and `require` returns `false`:
//!     the test returns, passing;
//!   - otherwise it panics with a message naming the missing component, how to install it
//!     and the opt-out.
//! - Where the component is there, [`require`] returns `true` and does nothing else.
//!
//! The test's name is its thread's (libtest and nextest name each test's thread after it).

use std::io::Write;
use std::path::Path;

/// The variable listing the components the user agrees to skip (comma-separated).
pub const SKIP_VAR: &str = "MIRRORBOX_TEST_SKIP";
/// The variable naming the file every skip appends its line to.
pub const SKIP_LOG_VAR: &str = "MIRRORBOX_SKIP_LOG";

/// Debian's `assimp-testmodels`, `/usr/share/assimp/models` (the OBJ and glTF corpus tests).
pub const CORPUS: &str = "corpus";
/// The X virtual framebuffer the viewer's window tests open their window on.
pub const XVFB: &str = "xvfb";
/// Real keyboard and mouse input through the X server (the viewer's input test).
pub const XDOTOOL: &str = "xdotool";
/// A local one-node Slurm (`scripts/slurm-local.sh`), which needs root.
pub const SLURM: &str = "slurm";
/// Mitsuba 3 in `tools/mitsuba/.venv`, named by `MIRRORBOX_MITSUBA_PYTHON`.
pub const MITSUBA: &str = "mitsuba";
/// `chromium-headless-shell` (the HTML reports' layout test).
pub const CHROMIUM: &str = "chromium";
/// An adapter with ray queries (`wgpu::Features::EXPERIMENTAL_RAY_QUERY`).
pub const RAYTRACING: &str = "raytracing";
/// Node.js and the web clients' npm packages (`clients/web`, issue 53's exchange).
pub const WEB: &str = "web";

/// Every component a test may need, with how to get it.
pub const COMPONENTS: [(&str, &str); 8] = [
    (
        CORPUS,
        "scripts/install-system-deps.sh installs Debian's assimp-testmodels",
    ),
    (XVFB, "scripts/install-system-deps.sh installs xvfb"),
    (XDOTOOL, "scripts/install-system-deps.sh installs xdotool"),
    (
        SLURM,
        "run scripts/test.sh as root: it installs and starts a local Slurm (scripts/slurm-local.sh)",
    ),
    (
        MITSUBA,
        "tools/mitsuba/setup.sh installs it; scripts/test.sh sets MIRRORBOX_MITSUBA_PYTHON",
    ),
    (
        CHROMIUM,
        "scripts/install-system-deps.sh installs chromium-headless-shell",
    ),
    (
        RAYTRACING,
        "Mesa ≥ 25's lavapipe has ray queries: scripts/install-system-deps.sh installs it",
    ),
    (
        WEB,
        "scripts/install-system-deps.sh installs nodejs and npm, scripts/install-web-clients.sh the pinned packages of clients/web",
    ),
];

/// What [`require`] decided.
#[derive(Debug, PartialEq, Eq)]
pub enum Decision {
    /// The component is there: the test runs.
    Present,
    /// Missing and named in the skip list: the test returns. The line for the skip log.
    Skipped { log_line: String },
    /// Missing and not named: the test fails with this message.
    Missing { message: String },
}

/// How to install `component`, in words.
pub fn install_hint(component: &str) -> &'static str {
    COMPONENTS
        .iter()
        .find(|(name, _)| *name == component)
        .map(|(_, how)| *how)
        .unwrap_or("see scripts/install-system-deps.sh")
}

/// Whether `component` is in the comma-separated `skip_list`.
pub fn listed(component: &str, skip_list: &str) -> bool {
    skip_list.split(',').any(|name| name.trim() == component)
}

/// The decision for `component` (`present` or not, missing because of `reason`) in test
/// `test`, given the skip list (the value of `MIRRORBOX_TEST_SKIP`, if set). Pure: no
/// environment read, nothing written.
pub fn decide(
    component: &str,
    present: bool,
    reason: &str,
    test: &str,
    skip_list: Option<&str>,
) -> Decision {
    if present {
        return Decision::Present;
    }
    if skip_list.is_some_and(|list| listed(component, list)) {
        let one_line = |s: &str| s.replace(['\t', '\n', '\r'], " ");
        return Decision::Skipped {
            log_line: format!("{component}\t{}\t{}\n", one_line(test), one_line(reason)),
        };
    }
    let now = match skip_list {
        Some(list) => format!(" (it is now {list:?})"),
        None => String::new(),
    };
    Decision::Missing {
        message: format!(
            "{test}: the test component `{component}` is missing: {reason}. To install it: {}. \
             To skip the tests that need it instead, set {SKIP_VAR}={component}{now}; \
             skipped tests are listed in the file named by {SKIP_LOG_VAR}",
            install_hint(component)
        ),
    }
}

/// The running test's name: its thread's, as libtest and nextest name it.
pub fn test_name() -> String {
    std::thread::current()
        .name()
        .unwrap_or("(unnamed test)")
        .to_string()
}

/// Appends `line` to the skip log at `path`, in one write (lines of tests running in parallel
/// processes do not interleave).
pub fn append_line(path: &Path, line: &str) -> std::io::Result<()> {
    std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)?
        .write_all(line.as_bytes())
}

/// Whether the test may go on: `true` where `present`. Where not, `false` if `component` is
/// in `MIRRORBOX_TEST_SKIP` (the skip printed and logged: see the crate's contract);
/// otherwise it panics, naming the component, how to install it and the opt-out (at the
/// caller's line).
///
/// ```text
/// if !mirrorbox_testing::require(XVFB, on_path("Xvfb"), "Xvfb is not installed") {
///     return;
/// }
/// ```
#[track_caller]
pub fn require(component: &str, present: bool, reason: &str) -> bool {
    let skip_list = std::env::var(SKIP_VAR).ok();
    match decide(
        component,
        present,
        reason,
        &test_name(),
        skip_list.as_deref(),
    ) {
        Decision::Present => true,
        Decision::Skipped { log_line } => {
            eprintln!("skipped: {component}: {reason}");
            if let Some(log) = std::env::var_os(SKIP_LOG_VAR) {
                let log = Path::new(&log);
                append_line(log, &log_line).unwrap_or_else(|e| {
                    panic!("cannot append to {SKIP_LOG_VAR} {}: {e}", log.display())
                });
            }
            false
        }
        Decision::Missing { message } => panic!("{message}"),
    }
}

/// Whether `program` is an executable file in a folder of `PATH` (or, holding a `/`, is one).
pub fn on_path(program: &str) -> bool {
    use std::os::unix::fs::PermissionsExt;
    let executable = |p: &Path| {
        p.metadata()
            .is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
    };
    if program.contains('/') {
        return executable(Path::new(program));
    }
    std::env::var_os("PATH").is_some_and(|paths| {
        std::env::split_paths(&paths).any(|dir| executable(&dir.join(program)))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_present_component_runs_whatever_the_list() {
        for list in [None, Some(""), Some("corpus,xvfb")] {
            assert_eq!(
                decide(CORPUS, true, "r", "t", list),
                Decision::Present,
                "{list:?}"
            );
        }
    }

    #[test]
    fn a_missing_component_fails_naming_it_its_install_and_the_opt_out() {
        for list in [None, Some(""), Some("xvfb, slurm"), Some("corpusx")] {
            let Decision::Missing { message } =
                decide(CORPUS, false, "no /usr/share/assimp/models", "m::t", list)
            else {
                panic!("{list:?}: not a failure");
            };
            for words in [
                "m::t: the test component `corpus` is missing: no /usr/share/assimp/models",
                "assimp-testmodels",
                "scripts/install-system-deps.sh",
                "MIRRORBOX_TEST_SKIP=corpus",
                "MIRRORBOX_SKIP_LOG",
            ] {
                assert!(message.contains(words), "{list:?}: {words:?} in {message}");
            }
        }
    }

    #[test]
    fn a_listed_missing_component_is_skipped_with_its_log_line() {
        for list in ["slurm", "xvfb,slurm", " corpus , slurm ,"] {
            assert_eq!(
                decide(SLURM, false, "not root\t(uid 1000)", "slurm::a", Some(list)),
                Decision::Skipped {
                    log_line: "slurm\tslurm::a\tnot root (uid 1000)\n".into()
                },
                "{list:?}"
            );
        }
    }

    #[test]
    fn every_component_has_its_install_hint() {
        for (name, how) in COMPONENTS {
            assert_eq!(install_hint(name), how);
            assert!(!how.is_empty() && !name.contains(','), "{name}");
        }
    }

    #[test]
    fn skip_lines_append_whole() {
        let path = std::env::temp_dir().join(format!("mirrorbox-skip-log-{}", std::process::id()));
        let _ = std::fs::remove_file(&path);
        append_line(&path, "corpus\ta\tr1\n").unwrap();
        append_line(&path, "xvfb\tb\tr2\n").unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(text, "corpus\ta\tr1\nxvfb\tb\tr2\n");
    }

    /// `require` itself, both ways, in child processes (the environment is the process's):
    /// the test binary runs this very test again with the variables set.
    #[test]
    fn require_skips_and_logs_only_what_is_listed() {
        const CHILD: &str = "MIRRORBOX_TESTING_CHILD";
        if std::env::var_os(CHILD).is_some() {
            let go_on = require(CHROMIUM, false, "no chromium here");
            assert!(!go_on, "a missing component never goes on");
            return;
        }
        assert_eq!(
            test_name(),
            "tests::require_skips_and_logs_only_what_is_listed"
        );
        let log = std::env::temp_dir().join(format!("mirrorbox-require-{}", std::process::id()));
        let _ = std::fs::remove_file(&log);
        let run = |list: &str| {
            std::process::Command::new(std::env::current_exe().unwrap())
                .args([
                    "--exact",
                    "tests::require_skips_and_logs_only_what_is_listed",
                    "--nocapture",
                    "--test-threads",
                    "2",
                ])
                .env(CHILD, "1")
                .env(SKIP_VAR, list)
                .env(SKIP_LOG_VAR, &log)
                .output()
                .unwrap()
        };
        let skipped = run("xvfb,chromium");
        let stderr = String::from_utf8_lossy(&skipped.stderr);
        assert!(skipped.status.success(), "{stderr}");
        assert!(
            stderr.contains("skipped: chromium: no chromium here"),
            "{stderr}"
        );
        assert_eq!(
            std::fs::read_to_string(&log).unwrap(),
            "chromium\ttests::require_skips_and_logs_only_what_is_listed\tno chromium here\n"
        );
        let failed = run("xvfb");
        let out = String::from_utf8_lossy(&failed.stdout).to_string()
            + &String::from_utf8_lossy(&failed.stderr);
        assert!(!failed.status.success(), "{out}");
        assert!(
            out.contains("the test component `chromium` is missing: no chromium here")
                && out.contains("MIRRORBOX_TEST_SKIP=chromium"),
            "{out}"
        );
        // Nothing more was logged by the failing run.
        assert_eq!(std::fs::read_to_string(&log).unwrap().lines().count(), 1);
        std::fs::remove_file(&log).unwrap();
    }

    #[test]
    fn on_path_finds_programs() {
        assert!(on_path("sh"));
        assert!(on_path("/bin/sh"));
        assert!(!on_path("mirrorbox-no-such-program"));
    }
}
