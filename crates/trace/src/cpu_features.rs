//! One binary, the CPU's widest vectors: code run through [`widest`] is compiled three
//! times — for AVX-512 (F with VL, BW and DQ, which every AVX-512 CPU since Skylake-SP has:
//! VL gives 8-lane compares into mask registers, which the traversals' 8-lane loops use;
//! not shown apart from F alone in `whitted`'s time, issue 56), for AVX2 and for the x86-64 baseline (SSE2) — and the CPU's best is
//! chosen at run time (`is_x86_feature_detected`, once). No `target-cpu=native`.
//!
//! Why it is safe for the answers: Rust never contracts `a * b + c` into a fused
//! multiply-add, and every vector instruction of add, multiply, divide and square root
//! rounds each lane as its scalar form does, so all three builds give the same bits.
//!
//! How it works: the work is a [`Vectorised`] value whose `run` is `#[inline(always)]`; it
//! is called from a function carrying `#[target_feature]`, and `run` and everything forced
//! inline into it are compiled with those features. (A closure does not do: it stays a
//! function of its own, compiled for the baseline, and the wrapper only jumps to it.) The
//! lane loops inside (`for i in 0..LANES`, branch free over structure-of-arrays data) are
//! what the wider vectors speed up.

/// Work to compile for each CPU: implement `run` with `#[inline(always)]`, and mark
/// `#[inline(always)]` what it calls that should be compiled with it.
pub trait Vectorised {
    type Output;
    fn run(self) -> Self::Output;
}

/// The builds [`widest`] chooses from, narrowest first (so `min` is the narrower).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Build {
    Baseline,
    Avx2,
    Avx512,
}

impl Build {
    /// Its name in reports and `--json` (`avx512`, `avx2`, `baseline`).
    pub fn name(self) -> &'static str {
        match self {
            Build::Avx512 => "avx512",
            Build::Avx2 => "avx2",
            Build::Baseline => "baseline",
        }
    }
}

/// A narrower build asked for before the first [`widest`] call ([`narrow_to`]).
static NARROWED: std::sync::OnceLock<Build> = std::sync::OnceLock::new();

/// Runs [`widest`]'s work on `build` instead of the CPU's widest: the narrower builds'
/// code timed on a wider CPU (`trace --simd`; a CPU's own record needs that CPU, and the
/// bench does not use it). Errors where the CPU lacks `build`, or where the build was
/// already chosen otherwise (by a first [`widest`] call, or an earlier request).
pub fn narrow_to(build: Build) -> Result<(), String> {
    let widest = detected();
    if build > widest {
        return Err(format!(
            "this CPU has no {} build (its widest is {})",
            build.name(),
            widest.name()
        ));
    }
    if *NARROWED.get_or_init(|| build) != build || *BUILD != build {
        return Err(format!(
            "the vector build was already chosen ({})",
            BUILD.name()
        ));
    }
    Ok(())
}

/// The build [`widest`] runs: the CPU's widest, or the narrower one asked for.
static BUILD: std::sync::LazyLock<Build> =
    std::sync::LazyLock::new(|| NARROWED.get().map_or(detected(), |&b| b.min(detected())));

/// This CPU's widest build.
fn detected() -> Build {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512vl")
            && std::arch::is_x86_feature_detected!("avx512bw")
            && std::arch::is_x86_feature_detected!("avx512dq")
        {
            return Build::Avx512;
        }
        if std::arch::is_x86_feature_detected!("avx2") {
            return Build::Avx2;
        }
    }
    Build::Baseline
}

/// Runs `work` compiled for the widest vector instructions this CPU has (or the narrower
/// build asked for, [`narrow_to`]).
#[inline(always)]
pub fn widest<W: Vectorised>(work: W) -> W::Output {
    match *BUILD {
        // SAFETY: the CPU has AVX-512F (detected at run time).
        #[cfg(target_arch = "x86_64")]
        Build::Avx512 => unsafe { x86::avx512(work) },
        // SAFETY: the CPU has AVX2 (detected at run time).
        #[cfg(target_arch = "x86_64")]
        Build::Avx2 => unsafe { x86::avx2(work) },
        _ => work.run(),
    }
}

/// The name of the build [`widest`] runs (reports, `--json`).
pub fn widest_name() -> &'static str {
    BUILD.name()
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::Vectorised;

    #[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
    pub fn avx512<W: Vectorised>(work: W) -> W::Output {
        work.run()
    }

    #[target_feature(enable = "avx2")]
    pub fn avx2<W: Vectorised>(work: W) -> W::Output {
        work.run()
    }
}
