//! This core's f32 peak: one thread, 12 independent chains of fused multiply-adds (enough
//! to cover the FMA units' latency), 16 lanes with AVX-512 and 8 with AVX2, each FMA
//! counted as two FLOPs. What `BENCHMARKS.md` measures the DQN update's GFLOP/s against.
//!
//! `cargo bench --bench fma_peak`

use std::hint::black_box;
use std::time::Instant;

/// FMAs per chain per measurement.
const ROUNDS: u64 = 50_000_000;

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn chains_avx512(rounds: u64) -> f32 {
    use std::arch::x86_64::*;
    let a = _mm512_set1_ps(0.999_999);
    let b = _mm512_set1_ps(1e-7);
    let mut acc = [_mm512_set1_ps(1.0); 12];
    for _ in 0..rounds {
        for x in acc.iter_mut() {
            *x = _mm512_fmadd_ps(*x, a, b);
        }
    }
    let mut total = _mm512_setzero_ps();
    for x in acc {
        total = _mm512_add_ps(total, x);
    }
    _mm512_reduce_add_ps(total)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn chains_avx2(rounds: u64) -> f32 {
    use std::arch::x86_64::*;
    let a = _mm256_set1_ps(0.999_999);
    let b = _mm256_set1_ps(1e-7);
    let mut acc = [_mm256_set1_ps(1.0); 12];
    for _ in 0..rounds {
        for x in acc.iter_mut() {
            *x = _mm256_fmadd_ps(*x, a, b);
        }
    }
    let mut lanes = [0.0f32; 8];
    let mut total = _mm256_setzero_ps();
    for x in acc {
        total = _mm256_add_ps(total, x);
    }
    _mm256_storeu_ps(lanes.as_mut_ptr(), total);
    lanes.iter().sum()
}

/// GFLOP/s of the best of five measurements.
fn peak(lanes: u64, run: impl Fn(u64) -> f32) -> f64 {
    black_box(run(ROUNDS / 10));
    (0..5)
        .map(|_| {
            let start = Instant::now();
            black_box(run(black_box(ROUNDS)));
            let flops = ROUNDS * 12 * lanes * 2;
            flops as f64 / start.elapsed().as_secs_f64() / 1e9
        })
        .fold(0.0, f64::max)
}

fn main() {
    #[cfg(target_arch = "x86_64")]
    {
        if is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has AVX-512F, checked above.
            let gflops = peak(16, |r| unsafe { chains_avx512(r) });
            println!("f32 peak, one thread, AVX-512 FMA: {gflops:.1} GFLOP/s");
        } else {
            println!("f32 peak, AVX-512: this CPU has no AVX-512F");
        }
        if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
            // SAFETY: the CPU has AVX2 and FMA, checked above.
            let gflops = peak(8, |r| unsafe { chains_avx2(r) });
            println!("f32 peak, one thread, AVX2 FMA: {gflops:.1} GFLOP/s");
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    println!("fma_peak measures x86-64's AVX-512 and AVX2 only");
}
