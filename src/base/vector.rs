//! Whether the kernels may use the processor's vector instructions: a switch for the whole
//! process. Each kernel that has a vector path (`soft`'s colour passes, `exact`'s pair times)
//! gives the same result bit for bit without it; `moving_circles run --vector off` is how a run
//! shows it.

use std::sync::atomic::{AtomicBool, Ordering};

static ALLOWED: AtomicBool = AtomicBool::new(true);

/// Lets the kernels use the processor's vector instructions where it has them (`true`, the
/// default), or has them go lane by lane on any processor (`false`), for this whole process.
pub fn allow(allowed: bool) {
    ALLOWED.store(allowed, Ordering::Relaxed);
}

/// Whether a kernel may take its AVX2 path: the processor has AVX2 and [`allow`] lets it.
#[inline]
pub fn avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        ALLOWED.load(Ordering::Relaxed) && std::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
