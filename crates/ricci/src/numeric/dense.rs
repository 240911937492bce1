//! Dense products with faer, followed by `vzeroupper` on the calling thread ([`super::simd`]):
//! faer's AVX kernels leave the upper register state dirty, which slows the baseline (SSE)
//! code that runs next on the same thread about tenfold.

use faer::Mat;

/// The Gram matrix `VᵀV`. faer may run parts of the product on other threads of the rayon
/// pool (global parallelism); only the calling thread is cleaned here, so a caller running many
/// products in a parallel phase calls [`super::simd::clear_upper_state`] after it.
pub fn gram(v: &Mat<f64>) -> Mat<f64> {
    let g = v.transpose() * v;
    super::simd::clear_upper_state_here();
    g
}
