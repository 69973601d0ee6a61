//! FNV-1a, 64 bit: a small, stable, dependency-free hash for content keys (scene hashes,
//! cache keys). Not for security; stable across runs, platforms and Rust versions.

/// Feed it text with `write!`/`write_str`, read it with [`Fnv1a::finish`].
#[derive(Clone, Copy, Debug)]
pub struct Fnv1a(u64);

impl Fnv1a {
    pub fn new() -> Self {
        Fnv1a(0xcbf2_9ce4_8422_2325)
    }
    pub fn finish(&self) -> u64 {
        self.0
    }
    /// Feeds raw bytes (a texture's texels), as `write_str` feeds a string's.
    pub fn write_bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}

impl Default for Fnv1a {
    fn default() -> Self {
        Self::new()
    }
}

impl std::fmt::Write for Fnv1a {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.write_bytes(s.as_bytes());
        Ok(())
    }
}

/// FNV-1a of `text`.
pub fn fnv1a(text: &str) -> u64 {
    let mut h = Fnv1a::new();
    std::fmt::Write::write_str(&mut h, text).expect("infallible");
    h.finish()
}

#[cfg(test)]
mod tests {
    #[test]
    fn published_test_vectors() {
        // From the FNV reference test suite (64-bit FNV-1a).
        assert_eq!(super::fnv1a(""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(super::fnv1a("a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(super::fnv1a("foobar"), 0x8594_4171_f739_67e8);
    }
}
