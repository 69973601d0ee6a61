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
/// `#[inline(always)]` what it calls that should be compiled with it. The builds call
/// [`Vectorised::run_wide`], which work shaped by the vector width implements instead (its
/// `run` is then what a caller outside the builds gets).
pub trait Vectorised {
    type Output;
    fn run(self) -> Self::Output;

    /// [`Vectorised::run`] in the build whose vectors hold `F32_LANES` f32 lanes (16 for
    /// AVX-512, 8 for AVX2, 4 for the baseline's SSE2): for work whose loops are shaped by
    /// the vector width (the packet kernel's triangle chunks). By default `run`.
    #[inline(always)]
    fn run_wide<const F32_LANES: usize>(self) -> Self::Output
    where
        Self: Sized,
    {
        self.run()
    }
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

/// The lanes `0..N` for which `flag(i)` holds, as bits (bit `i`): a lane loop's answer.
///
/// Why not the plain fold `bits |= (flag(i) as u32) << i`: the compiler vectorises it, and
/// in the AVX2 build turns it into one `vmovmskps` per 8 lanes; in the AVX-512 build, where
/// the comparisons land in mask registers, it selects powers of two under the mask and ORs
/// them across the vector — nine instructions and their latency after every box test
/// instead of one `kmov` (seen in the disassembly, issue 56). Here each lane becomes 0 or
/// −1 and SSE's `movmskps` (in every x86-64 build) reads their sign bits four lanes at a
/// time: the compiler folds that into `kmov` from the comparison's mask register in the
/// AVX-512 build, and keeps `movmskps` in the others. The same bits (tested).
///
/// Used by the 8-wide traversal's box test: `path` ×0.966 / ×0.978 on `mirror_room` /
/// `mirror_box` (docs/tracer-performance.md). Not by the packet kernel's 16 and 32 lanes:
/// there the compiler split the comparisons into 4-lane pieces (`whitted` ×1.03–1.04
/// slower), and AVX-512's `vpmovd2m` behind a run-time check of the build, which gave one
/// `kmovw`, was ×1.02 slower too.
#[inline(always)]
#[allow(clippy::needless_range_loop)]
pub fn lane_bits<const N: usize>(flag: impl Fn(usize) -> bool) -> u32 {
    const { assert!(N <= 32 && N.is_multiple_of(4)) };
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_loadu_ps, _mm_movemask_ps};
        let mut m = [0i32; N];
        for i in 0..N {
            m[i] = -(flag(i) as i32);
        }
        let mut bits = 0u32;
        let mut c = 0;
        while c < N {
            // SAFETY: lanes c..c + 4 are in `m` (N is a multiple of 4); SSE is part of every
            // x86-64 build.
            let v = unsafe { _mm_loadu_ps(m.as_ptr().add(c).cast()) };
            bits |= (unsafe { _mm_movemask_ps(v) } as u32) << c;
            c += 4;
        }
        bits
    }
    #[cfg(not(target_arch = "x86_64"))]
    lane_bits_fold::<N>(flag)
}

/// [`lane_bits`] as the plain fold (other architectures; tests).
#[inline(always)]
#[cfg_attr(target_arch = "x86_64", allow(dead_code))]
fn lane_bits_fold<const N: usize>(flag: impl Fn(usize) -> bool) -> u32 {
    let mut bits = 0u32;
    for i in 0..N {
        bits |= (flag(i) as u32) << i;
    }
    bits
}

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

/// Whether 512-bit instructions lower this CPU's clock for the code around them: Intel's
/// AVX-512 frequency licences (a core that runs them steps its clock down for a while after).
/// AMD's AVX-512 CPUs (Zen 4 and 5) keep their clock, so only Intel CPUs count.
static WIDE_VECTORS_SLOW_THE_CLOCK: std::sync::LazyLock<bool> = std::sync::LazyLock::new(|| {
    #[cfg(target_arch = "x86_64")]
    {
        // Leaf 0: the vendor string in EBX, EDX, ECX.
        let id = std::arch::x86_64::__cpuid(0);
        [id.ebx, id.edx, id.ecx] == [0x756e_6547, 0x4965_6e69, 0x6c65_746e] // "GenuineIntel"
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
});

/// The build [`widest`] runs, but AVX2 in place of AVX-512 for work that does not
/// `gain_from_512_bits` on a CPU whose clock 512-bit vectors slow
/// ([`WIDE_VECTORS_SLOW_THE_CLOCK`]), unless AVX-512 was asked for by name ([`narrow_to`]):
/// the build for [`run_on`], the same for all of a render's work (the image row, the camera
/// rays, the integrator's walk), since a 512-bit loop anywhere in it slows all of it.
pub fn build_for(gains_from_512_bits: bool) -> Build {
    choose(
        *BUILD,
        gains_from_512_bits,
        NARROWED.get().is_some(),
        *WIDE_VECTORS_SLOW_THE_CLOCK,
    )
}

/// [`build_for`]'s rule: `build` (the widest, or the one asked for by name when `asked`),
/// but AVX2 for AVX-512 where the work does not gain from 512 bits and they slow the clock.
fn choose(build: Build, gains_from_512_bits: bool, asked: bool, slows_clock: bool) -> Build {
    if build == Build::Avx512 && !gains_from_512_bits && !asked && slows_clock {
        Build::Avx2
    } else {
        build
    }
}

/// Whether this CPU can run `build` (`trace --simd`; tests).
pub fn cpu_has(build: Build) -> bool {
    build <= detected()
}

/// Runs `work` compiled for the widest vector instructions this CPU has (or the narrower
/// build asked for, [`narrow_to`]).
#[inline(always)]
pub fn widest<W: Vectorised>(work: W) -> W::Output {
    run_on(*BUILD, work)
}

/// Runs `work` compiled for `build` ([`build_for`]'s), or for [`widest`]'s where `build` is
/// wider (never code this CPU cannot run).
#[inline(always)]
pub fn run_on<W: Vectorised>(build: Build, work: W) -> W::Output {
    match build.min(*BUILD) {
        // SAFETY: the CPU has AVX-512F (detected at run time).
        #[cfg(target_arch = "x86_64")]
        Build::Avx512 => unsafe { x86::avx512(work) },
        // SAFETY: the CPU has AVX2 (detected at run time).
        #[cfg(target_arch = "x86_64")]
        Build::Avx2 => unsafe { x86::avx2(work) },
        _ => work.run_wide::<4>(),
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::Vectorised;

    #[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq")]
    pub fn avx512<W: Vectorised>(work: W) -> W::Output {
        work.run_wide::<16>()
    }

    #[target_feature(enable = "avx2")]
    pub fn avx2<W: Vectorised>(work: W) -> W::Output {
        work.run_wide::<8>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// AVX2 in place of AVX-512 only for work that does not gain from 512 bits, on a CPU whose
    /// clock they slow, when no build was asked for by name; every other case keeps its build.
    #[test]
    fn only_unasked_work_without_gain_narrows_where_the_clock_slows() {
        use Build::*;
        for build in [Baseline, Avx2, Avx512] {
            for gains in [false, true] {
                for asked in [false, true] {
                    for slows in [false, true] {
                        let narrowed = build == Avx512 && !gains && !asked && slows;
                        assert_eq!(
                            choose(build, gains, asked, slows),
                            if narrowed { Avx2 } else { build },
                            "{build:?} gains {gains} asked {asked} slows {slows}"
                        );
                    }
                }
            }
        }
    }

    /// Bit `i` of `lane_bits(flag)` is `flag(i)`, for the lane counts the traversals use
    /// and others, in the baseline build and in the widest this CPU has: a lane moved or
    /// dropped fails it.
    #[test]
    fn lane_bits_are_the_flags() {
        fn check<const N: usize>(seed: u64) {
            struct Bits<'f, const N: usize>(&'f [bool; N]);
            impl<const N: usize> Vectorised for Bits<'_, N> {
                type Output = u32;
                #[inline(always)]
                fn run(self) -> u32 {
                    lane_bits::<N>(|i| self.0[i])
                }
            }
            let mut rng = crate::sampler::SplitMix64::for_pixel(seed, N as u64);
            for _ in 0..200 {
                let flags: [bool; N] = std::array::from_fn(|_| rng.next_unit() < 0.5);
                let expected = (0..N).fold(0u32, |m, i| m | u32::from(flags[i]) << i);
                assert_eq!(
                    lane_bits::<N>(|i| flags[i]),
                    expected,
                    "{N} lanes: {flags:?}"
                );
                assert_eq!(widest(Bits(&flags)), expected, "{N} lanes: {flags:?}");
                assert_eq!(lane_bits_fold::<N>(|i| flags[i]), expected);
            }
        }
        println!("vector build: {}", BUILD.name());
        check::<4>(1);
        check::<8>(3);
        check::<12>(4);
        check::<16>(5);
        check::<32>(7);
    }
}
