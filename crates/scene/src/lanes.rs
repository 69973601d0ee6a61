//! Lane loops' stores (the trace crate's walks and this crate's lane functions, such as
//! [`crate::shading::Lighting::direct_radiance_lanes`], run their loops over structure of
//! arrays, compiled for each CPU's vectors by the trace crate's `cpu_features::widest`).

/// `*dst = value`, written with plain vector stores (a blend, then a store), never a
/// masked store.
///
/// Why: LLVM 22 (rustc 1.95) rewrites a lane loop's `dst[i] = if c { x } else { dst[i] }`
/// — a store of a select whose other side is a load of the same place — into a masked
/// store (`foldToMaskedStore`, llvm-project#145176), and in the AVX2 build that is
/// `vmaskmovps`/`vmaskmovpd`, which AMD's Zen 1–3 run as microcode: on the Zen 3 of issue
/// 56's AVX2 record a 256-bit masked store took 3–6 ns where a plain one takes 0.65 ns (a
/// C loop of 32 stores). LLVM later stopped the fold on those CPUs (llvm-project#214187,
/// not in rustc 1.95's LLVM). Here the place's address passes through an empty `asm!`
/// (pure, no memory access), so the compiler cannot see that it writes the place it loaded,
/// and the select stays a blend. The same bits in every build; in the AVX-512 build, where
/// a masked store is cheap, a blend is too.
#[inline(always)]
pub fn store_lanes<T: Copy, const N: usize>(dst: &mut [T; N], value: [T; N]) {
    #[cfg(target_arch = "x86_64")]
    {
        let place: *mut [T; N] = dst;
        let mut address = place.addr();
        // SAFETY: the empty template returns its input unchanged and touches no memory,
        // stack or flags.
        unsafe {
            std::arch::asm!("/* {0} */", inout(reg) address, options(pure, nomem, nostack, preserves_flags));
        }
        // SAFETY: `address` is `dst`'s, and the pointer keeps `dst`'s provenance (a unique
        // borrow): this writes `*dst`.
        unsafe { place.with_addr(address).write(value) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        *dst = value;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every lane is written, and only the array given: the select of a lane loop stored
    /// whole, as `*dst = value` would.
    #[test]
    fn store_lanes_writes_every_lane_and_nothing_else() {
        let mut rows = [[1.0f32; 8]; 3];
        let old = rows[1];
        let new: [f32; 8] = std::array::from_fn(|i| if i % 3 == 0 { i as f32 } else { old[i] });
        store_lanes(&mut rows[1], new);
        assert_eq!(rows[1], new);
        assert_eq!(rows[0], [1.0; 8]);
        assert_eq!(rows[2], [1.0; 8]);
        let mut bits = [u64::MAX; 4];
        store_lanes(&mut bits, [0, 1, 2, 3]);
        assert_eq!(bits, [0, 1, 2, 3]);
    }
}
