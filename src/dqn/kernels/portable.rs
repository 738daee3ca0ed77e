//! The products in plain Rust: the reference the vector paths must match bit for bit, and
//! the path of CPUs without AVX2 (on ARM, `mul_add` is one instruction and the inner loop
//! vectorises).

use super::{Finish, Product};

pub(super) fn product(p: &Product, out: &mut [f32], out_stride: usize) {
    for r in 0..p.rows {
        let row = &mut out[r * out_stride..][..p.columns];
        for (j, acc) in row.iter_mut().enumerate() {
            *acc = p.start.at(r, j);
        }
        for k in 0..p.depth {
            let l = p.left.at(r, k);
            let right = &p.right[k * p.right_stride..][..p.columns];
            for (acc, &x) in row.iter_mut().zip(right) {
                *acc = l.mul_add(x, *acc);
            }
        }
        match p.finish {
            Finish::Keep => {}
            Finish::Relu => {
                for x in row.iter_mut() {
                    *x = if *x > 0.0 { *x } else { 0.0 };
                }
            }
            Finish::MaskBy(by) => {
                let by = &by[r * out_stride..][..p.columns];
                for (x, &a) in row.iter_mut().zip(by) {
                    *x = if a > 0.0 { *x } else { 0.0 };
                }
            }
        }
    }
}
