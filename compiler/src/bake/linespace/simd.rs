//! Which vector instructions the bake's kernels use: the widest the CPU has, detected at run
//! time (a release build targets baseline x86-64, so a compile runs on any CPU and writes the
//! same bytes on each: every kernel has a portable twin with the same arithmetic).

/// The vector instructions a kernel uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Simd {
    None,
    Avx2,
    /// AVX-512F with BMI2 (which every CPU with AVX-512 has).
    Avx512,
}

impl Simd {
    /// The widest this CPU has.
    pub(super) fn detect() -> Simd {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f") && std::arch::is_x86_feature_detected!("bmi2") {
                return Simd::Avx512;
            }
            if std::arch::is_x86_feature_detected!("avx2") {
                return Simd::Avx2;
            }
        }
        Simd::None
    }

    /// This CPU's kinds, narrowest first (for tests comparing each with the portable code).
    #[cfg(test)]
    pub(super) fn available() -> &'static [Simd] {
        match Simd::detect() {
            Simd::Avx512 => &[Simd::None, Simd::Avx2, Simd::Avx512],
            Simd::Avx2 => &[Simd::None, Simd::Avx2],
            Simd::None => &[Simd::None],
        }
    }
}
