//! `mirrorbox view` in a binary built without the `viewer` feature (`cargo build
//! --no-default-features`, as `scripts/run.sh` builds it: the main job draws no window, and
//! the window's crates are about a third of a cold release build). It takes any arguments and
//! says how to build the viewer.

use crate::Failure;

#[derive(clap::Args)]
pub struct Args {
    /// The viewer's arguments (docs/viewer.md), accepted and not read: this binary has no
    /// viewer.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    arguments: Vec<String>,
}

/// What `view` says in a binary without the viewer.
pub const NOT_BUILT: &str = "this mirrorbox was built without the viewer (`--no-default-features`: \
     scripts/run.sh builds it so, to keep the main job within its time budget); build it with \
     the viewer with `cargo build --release -p mirrorbox`";

pub fn run(_: &Args) -> Result<(), Failure> {
    Err(Failure::BadInput(NOT_BUILT.into()))
}
