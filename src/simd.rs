//! Which vector instruction set the hot loops run with, chosen once at run time.
//!
//! The default release build targets baseline x86-64 (SSE2), which lacks the 32-bit integer
//! multiply, min/max and sign extension that tidepool's loops need, so the compiler leaves
//! them scalar. Hot loops are therefore compiled a few times with `#[target_feature]`, and
//! [`Simd::detect`] picks the widest version this CPU runs: the binary is portable and still
//! fast on any x86-64.

/// A vector instruction set.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Simd {
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
    /// The widest instruction set this CPU runs (detected once). `TIDEPOOL_SIMD=portable|
    /// sse4.1|avx2` caps it, for benchmarks and for comparing the paths.
    pub fn detect() -> Simd {
        #[cfg(target_arch = "x86_64")]
        {
            static DETECTED: std::sync::OnceLock<Simd> = std::sync::OnceLock::new();
            *DETECTED.get_or_init(|| {
                let cap = std::env::var("TIDEPOOL_SIMD").unwrap_or_default();
                let allowed = |level: &str| {
                    let order = ["portable", "sse4.1", "avx2", "avx512"];
                    let cap = order.iter().position(|l| *l == cap).unwrap_or(order.len());
                    order.iter().position(|l| *l == level).is_some_and(|i| i <= cap)
                };
                if allowed("avx512") && std::is_x86_feature_detected!("avx512bw") {
                    Simd::Avx512
                } else if allowed("avx2") && std::is_x86_feature_detected!("avx2") {
                    Simd::Avx2
                } else if allowed("sse4.1") && std::is_x86_feature_detected!("sse4.1") {
                    Simd::Sse41
                } else {
                    Simd::Portable
                }
            })
        }
        #[cfg(not(target_arch = "x86_64"))]
        Simd::Portable
    }
}
