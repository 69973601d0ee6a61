//! Stores for lane loops that keep LLVM from turning a select written back in place into a
//! masked store ([`store_unmasked`]). The lane loops are the trace crate's walks and this
//! crate's lane functions (such as [`crate::shading::Lighting::direct_radiance_lanes`]),
//! compiled for each CPU's vectors by the trace crate's `cpu_features::widest`.

/// `*dst = value`, through a pointer the compiler cannot see is `dst`: a lane loop that
/// computes `value[i] = if c { x } else { dst[i] }` and stores it here is compiled as a blend
/// and a plain store, not as a masked store.
///
/// Why: LLVM 22 (rustc 1.95) rewrites a store of a select whose other side is a load of the
/// same place into a masked store (`foldToMaskedStore`, llvm-project#145176), and in the
/// AVX2 build that is `vmaskmovps`/`vmaskmovpd`, which AMD's Zen 1–3 run as microcode: on the
/// Zen 3 of issue 56's AVX2 record a 256-bit masked store took 3–6 ns of throughput each
/// where a plain one takes 0.65 ns (a C loop of 32 independent stores). LLVM later stopped
/// the fold on those CPUs (llvm-project#214187, not in rustc 1.95's LLVM). Here `dst`'s
/// address passes through an empty `asm!` (pure, no memory access), so the store is not
/// known to go where the select's load came from. The same bits in every build. In the
/// AVX-512 build, where masked stores are single instructions on mask registers, a blend is
/// assumed as cheap (not measured: no AVX-512 CPU was at hand). A side effect: the address
/// escapes into the `asm!`, so the compiler keeps `dst` in memory.
///
/// A caller's loop must itself write a fresh array (`new[i] = if c { x } else { old[i] }`),
/// not update a copy in place, or the fold can come back on that copy;
/// `scripts/check-masked-stores.sh` counts the masked stores left in a build.
#[inline(always)]
pub fn store_unmasked<T: Copy, const N: usize>(dst: &mut [T; N], value: [T; N]) {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    {
        let place: *mut [T; N] = dst;
        let mut address = place.addr();
        // SAFETY: the template is empty: it returns `address` unchanged in the same register
        // and touches no memory, stack or flags (any other template would break the write
        // below).
        unsafe {
            std::arch::asm!("/* {0} */", inout(reg) address, options(pure, nomem, nostack, preserves_flags));
        }
        // SAFETY: `address` is `dst`'s own (the empty template above), and `with_addr` keeps
        // `dst`'s provenance, a unique borrow of a `[T; N]`: this writes `*dst`, aligned and in
        // bounds. `T: Copy`, so no old value needed dropping.
        unsafe { place.with_addr(address).write(value) };
    }
    #[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
    {
        *dst = value;
    }
}

/// `value` in the lanes of `dst` whose bit is set in `mask` (bit `i`: lane `i`), the others
/// as they are: a lane loop, stored by [`store_unmasked`].
#[inline(always)]
pub fn set_lanes<T: Copy, const N: usize>(dst: &mut [T; N], mask: u32, value: T) {
    let mut new = [value; N];
    for (lane, (n, &old)) in new.iter_mut().zip(dst.iter()).enumerate() {
        *n = if mask >> lane & 1 == 1 { value } else { old };
    }
    store_unmasked(dst, new);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every lane is written, and only the array given: the select of a lane loop stored
    /// whole, as `*dst = value` would.
    #[test]
    fn store_unmasked_writes_every_lane_and_nothing_else() {
        let mut rows = [[1.0f32; 8]; 3];
        let old = rows[1];
        let new: [f32; 8] = std::array::from_fn(|i| if i % 3 == 0 { i as f32 } else { old[i] });
        store_unmasked(&mut rows[1], new);
        assert_eq!(rows[1], new);
        assert_eq!(rows[0], [1.0; 8]);
        assert_eq!(rows[2], [1.0; 8]);
        let mut bits = [u64::MAX; 4];
        store_unmasked(&mut bits, [0, 1, 2, 3]);
        assert_eq!(bits, [0, 1, 2, 3]);
    }

    /// The lanes of the mask take the value, the others keep theirs.
    #[test]
    fn set_lanes_sets_the_masked_lanes_only() {
        let mut a = [7u32; 8];
        set_lanes(&mut a, 0b1010_0001, 3);
        assert_eq!(a, [3, 7, 7, 7, 7, 3, 7, 3]);
    }
}
