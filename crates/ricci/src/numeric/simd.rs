//! Vector-register hygiene after faer's dense kernels.
//!
//! faer's matrix kernels (the `gemm` microkernels) use AVX / AVX-512 when the CPU has them and
//! can return with the upper halves of the vector registers dirty. The rest of this crate is
//! compiled for the x86-64 baseline, i.e. with legacy-SSE encodings, and on Intel cores every
//! such instruction then carries a false dependency on the dirty upper state. Measured on the
//! 2-core Xeon VM: after the spline fit's per-triangle Gram products the double-double spline
//! evaluation ran 10× slower on the threads that had run a kernel (continuity report of the
//! demo surface 0.20 s → 2.2 s, until the process ended). `vzeroupper` on every thread of the
//! pool restores the clean state: [`clear_upper_state`] after kernels that may have run on the
//! pool, [`clear_upper_state_here`] after sequential ones. The library calls them only inside
//! the faer wrappers of [`super::sparse`] and [`super::dense`]; code that calls faer's
//! factorizations or dense products directly must call them itself.

/// Execute `vzeroupper` on the calling thread (when the CPU has AVX): after a sequential faer
/// factorisation or solve (`Par::Seq`), which ran its kernels on this thread only.
#[inline]
pub fn clear_upper_state_here() {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: as in `clear_upper_state`.
            unsafe { std::arch::x86_64::_mm256_zeroupper() };
        }
    }
}

/// Execute `vzeroupper` on the calling thread and on every thread of the current rayon pool
/// (when the CPU has AVX; otherwise, and on other architectures, nothing to do). Call it from
/// outside the pool, after a phase that ran faer's dense kernels.
pub fn clear_upper_state() {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: `vzeroupper` needs AVX, which was just detected; it only zeroes the
            // upper halves of the vector registers, which no live value occupies between
            // two statements of safe code.
            let clear = || unsafe { std::arch::x86_64::_mm256_zeroupper() };
            rayon::broadcast(|_| clear());
            clear();
        }
    }
}
