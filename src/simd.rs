//! Which vector instruction set the hot loops run with.
//!
//! The default release build targets baseline x86-64 (SSE2), which lacks the 32-bit integer
//! multiply, min/max and sign extension that tidepool's loops need, so the compiler leaves
//! them scalar. Hot loops are therefore compiled a few times with `#[target_feature]`, and a
//! [`Simd`] value picks one. A `Simd` can only be had from [`Simd::detect`],
//! [`Simd::supported`] or [`Simd::PORTABLE`], so holding one proves this CPU runs it: that is
//! what makes calling the `#[target_feature]` functions it selects sound.
//!
//! Every tier gives the same bytes (the kernels are the same code, compiled with wider
//! vectors); the tests run each tier this CPU supports against the portable one.

/// A vector instruction set this CPU runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Simd(Tier);

/// The tiers, narrowest first. Private: a tier is only reachable through a checked [`Simd`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) enum Tier {
    /// The baseline x86-64 (SSE2) or non-x86 build.
    Portable,
    /// SSE4.1: 128-bit vectors with sign extension and 32-bit min/max.
    #[cfg(target_arch = "x86_64")]
    Sse41,
    /// AVX2: 256-bit vectors.
    #[cfg(target_arch = "x86_64")]
    Avx2,
    /// AVX-512BW: 512-bit vectors.
    #[cfg(target_arch = "x86_64")]
    Avx512,
}

impl Simd {
    /// The baseline every CPU of the target runs.
    pub const PORTABLE: Simd = Simd(Tier::Portable);

    /// Every tier this CPU runs, narrowest first (always starting with [`Simd::PORTABLE`]).
    pub fn supported() -> Vec<Simd> {
        let mut tiers = vec![Simd::PORTABLE];
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("sse4.1") {
                tiers.push(Simd(Tier::Sse41));
            }
            if std::is_x86_feature_detected!("avx2") {
                tiers.push(Simd(Tier::Avx2));
            }
            if std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("avx512bw") {
                tiers.push(Simd(Tier::Avx512));
            }
        }
        tiers
    }

    /// The widest tier this CPU runs (detected once). `TIDEPOOL_SIMD=portable|sse4.1|avx2|
    /// avx512` caps it, for benchmarks and for comparing the paths from outside.
    pub fn detect() -> Simd {
        static DETECTED: std::sync::OnceLock<Simd> = std::sync::OnceLock::new();
        *DETECTED.get_or_init(|| {
            let cap = std::env::var("TIDEPOOL_SIMD").unwrap_or_default();
            let supported = Simd::supported();
            match supported.iter().position(|s| s.name() == cap) {
                Some(i) => supported[i],
                None => *supported.last().expect("portable is always supported"),
            }
        })
    }

    /// The tier's name, as `TIDEPOOL_SIMD` spells it.
    pub fn name(self) -> &'static str {
        match self.0 {
            Tier::Portable => "portable",
            #[cfg(target_arch = "x86_64")]
            Tier::Sse41 => "sse4.1",
            #[cfg(target_arch = "x86_64")]
            Tier::Avx2 => "avx2",
            #[cfg(target_arch = "x86_64")]
            Tier::Avx512 => "avx512",
        }
    }

    /// The tier, for a kernel's dispatch.
    pub(crate) fn tier(self) -> Tier {
        self.0
    }
}

impl std::fmt::Display for Simd {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiers_are_checked_and_ordered() {
        let tiers = Simd::supported();
        assert_eq!(tiers[0], Simd::PORTABLE);
        assert!(tiers.windows(2).all(|w| w[0].tier() < w[1].tier()), "narrowest first: {tiers:?}");
        assert!(tiers.contains(&Simd::detect()));
        assert!(tiers.iter().all(|t| !t.name().is_empty()));
    }
}
